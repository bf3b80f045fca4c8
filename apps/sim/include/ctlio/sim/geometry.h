// Ray casting against the solid primitives the simulated worlds are built from
// (docs/user-guide/simulator.md): axis-aligned boxes, vertical cylinders, spheres, horizontal
// planes and one bilinear height field, with a uniform 2-D grid over the finite primitives.
//
// Every intersection is analytic: slab test for boxes, circle/quadratic for cylinders and
// spheres, and for the height field a 2-D DDA over its cells with the exact root of the quadratic
// z(t) = h(x(t), y(t)) in each cell (a bilinear patch restricted to a line is a quadratic).
// Primitives are solid: a ray starting inside one reports its exit, never a hit at t ≤ 0.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::sim {

struct RayHit {
  double t = std::numeric_limits<double>::infinity();  // range along the unit direction
  Vec3 normal = Vec3::Zero();                          // outward unit normal of the surface
  bool Valid() const { return t < std::numeric_limits<double>::infinity(); }
};

struct Box {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  // The box spanned by two opposite corners given in any order.
  static Box Spanning(const Vec3& a, const Vec3& b) { return {a.cwiseMin(b), a.cwiseMax(b)}; }
};

// Vertical cylinder (axis along z): a pole, a tree trunk.
struct Cylinder {
  Vec3 base = Vec3::Zero();  // centre of the bottom disc
  double radius = 0.0;
  double height = 0.0;
};

struct Sphere {
  Vec3 centre = Vec3::Zero();
  double radius = 0.0;
};

// Heights on a regular grid, bilinear in each cell; solid below the surface. Outside its xy
// extent the field does not exist (rays pass).
struct HeightField {
  double x0 = 0.0, y0 = 0.0, cell = 1.0;
  int nx = 0, ny = 0;                                    // cells; (nx + 1) × (ny + 1) nodes
  std::vector<double> z;                                 // node (i, j) at z[j * (nx + 1) + i]
  double top = std::numeric_limits<double>::infinity();  // max of z: UpdateTop() after filling
  static constexpr int kBlock = 8;
  std::vector<double> block_top;  // max of z over each kBlock × kBlock block of cells
  void UpdateTop();
  double Node(int i, int j) const { return z[size_t(j) * size_t(nx + 1) + size_t(i)]; }
  double Height(double x, double y) const;  // bilinear; NaN outside the extent
};

// Entry hits along o + t·d (d unit) with t ∈ (0, t_max); RayHit::t = +inf when none.
RayHit IntersectBox(const Box& b, const Vec3& o, const Vec3& d, double t_max);
// The same with the ray's componentwise inverse direction precomputed (one per ray, not per box).
RayHit IntersectBox(const Box& b, const Vec3& o, const Vec3& d, const Vec3& inv_d, double t_max);
RayHit IntersectCylinder(const Cylinder& c, const Vec3& o, const Vec3& d, double t_max);
RayHit IntersectSphere(const Sphere& s, const Vec3& o, const Vec3& d, double t_max);
RayHit IntersectHeightField(const HeightField& h, const Vec3& o, const Vec3& d, double t_max);

// A world's geometry. Build() must be called after the primitives are added.
class Scene {
 public:
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;
  std::vector<double> floors;    // solid half-spaces z ≤ value (the ground)
  std::vector<double> ceilings;  // solid half-spaces z ≥ value
  std::vector<HeightField> fields;

  // Bins the finite primitives into square xy cells of `cell` metres.
  void Build(double cell);
  RayHit Cast(const Vec3& o, const Vec3& d, double t_max) const;
  // True when p lies inside a solid (or below the ground / a height field).
  bool Occupied(const Vec3& p) const;
  // Axis-aligned bounds of the finite primitives (for pictures and the grid).
  Box Bounds() const { return bounds_; }

 private:
  enum Kind : uint32_t { kBox = 0, kCylinder = 1, kSphere = 2 };
  struct Ref {
    uint32_t kind, index;
  };
  Box bounds_;
  double cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> cell_start_;  // CSR: refs of cell c are refs_[cell_start_[c] ...)
  std::vector<Ref> refs_;
  std::vector<Ref> large_;  // tested once per ray, not binned
  RayHit IntersectRef(const Ref& r, const Vec3& o, const Vec3& d, const Vec3& inv_d,
                      double t_max) const;
};

}  // namespace ctlio::sim
