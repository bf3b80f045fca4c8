// Ray casting against the solid primitives the simulated worlds are built from
// (docs/user-guide/simulator.md): axis-aligned boxes, vertical cylinders, spheres, horizontal
// planes and one bilinear height field, with a uniform 2-D grid over the finite primitives.
//
// Every intersection is analytic: slab test for boxes, circle/quadratic for cylinders and
// spheres, and for the height field a 2-D DDA over its cells with the exact root of the quadratic
// z(t) = h(x(t), y(t)) in each cell (a bilinear patch restricted to a line is a quadratic).
// Primitives are solid: a ray starting inside one reports its exit, never a hit at t ≤ 0.
//
// Besides solids, a scene may hold what real recordings are full of and solids cannot model
// (docs/user-guide/simulator.md, "Realistic content"):
//   * scattering media (foliage, hedges): ellipsoids or boxes that are not solid; a ray entering
//     one returns at an exponentially distributed depth s ~ Exp(free_path) along its chord, or
//     passes through when s exceeds the chord (Beer–Lambert: a fraction exp(−chord/free_path)
//     of the rays sees what lies behind);
//   * ground cover (grass): inside xy rectangles, a layer of `height` over the ground (floors and
//     height fields) that is such a medium;
//   * micro-relief: the ground's hits are raised by δz(x, y), a smooth field of amplitude
//     `relief` (value noise on a 0.6 m lattice), along the ray: t' = t − δz/|d_z| (clamped);
//   * glass: boxes that stop a ray without a return (windows; the ray gives no point);
//   * moving people: upright cylinders (body) walking back and forth between two points at a
//     constant speed, placed by the time of the ray (Cast with a time).
// The random depth is a pure function of (scene seed, the ray's origin and direction bits, the
// medium): the same ray always gets the same return, so a scan is still a pure function of the
// seeds and the scan index. A scene without these gives exactly the hits it gave before.
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

// A volume of scattering medium: an ellipsoid with semi-axes `radii` (along x, y, z) or, with
// `box`, the axis-aligned box centre ± radii.
struct Medium {
  Vec3 centre = Vec3::Zero();
  Vec3 radii = Vec3::Ones();
  double free_path = 0.5;  // mean depth of a return inside [m]
  bool box = false;
};

// Grass over the ground inside [x0, x1] × [y0, y1].
struct GroundCover {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
  double height = 0.1;      // layer thickness [m]
  double free_path = 0.05;  // mean depth of a return inside, along the ray [m]
  double relief = 0.0;      // extra micro-relief under the cover (tussocks, 0.25 m lattice) [m]
};

// A person walking back and forth along a → b (ground points) at `speed`: at time τ the arc
// length s = (speed·τ + phase) mod 2L (L = |b − a|) puts them at a + min(s, 2L − s)/L·(b − a).
struct Mover {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  double speed = 1.3, phase = 0.0;  // m/s, m
  double radius = 0.22, height = 1.75;
  Vec3 At(double time) const;  // the ground point under the person
};

// Uniform in [0, 1) from the ray (origin and direction bits), the scene seed and a salt.
double RayUniform(uint64_t seed, const Vec3& o, const Vec3& d, uint64_t salt);

// A world's geometry. Build() must be called after the primitives are added.
class Scene {
 public:
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;
  std::vector<double> floors;    // solid half-spaces z ≤ value (the ground)
  std::vector<double> ceilings;  // solid half-spaces z ≥ value
  std::vector<HeightField> fields;
  std::vector<Medium> media;
  std::vector<GroundCover> covers;
  std::vector<Box> glass;
  std::vector<Mover> movers;  // not in Occupied(): the guide paths keep clear of their lanes
  double relief = 0.0;        // micro-relief amplitude of the ground [m]
  uint64_t seed = 0;          // of the per-ray draws in media and ground cover

  // Bins the finite primitives into square xy cells of `cell` metres.
  void Build(double cell);
  RayHit Cast(const Vec3& o, const Vec3& d, double t_max) const;
  // The same with the moving people at `time`.
  RayHit Cast(const Vec3& o, const Vec3& d, double t_max, double time) const;
  // True when p lies on or in a moving person at `time` (within 1 mm).
  bool OnMover(const Vec3& p, double time) const;
  // True when p lies inside a solid (or below the ground / a height field).
  bool Occupied(const Vec3& p) const;
  // True when p lies in a scattering medium, in the ground cover or within the relief of the
  // ground (where the returns of those lie, off the solids).
  bool InMedium(const Vec3& p) const;
  // The relief's height offset δz at (x, y) (0 without relief).
  double Relief(double x, double y) const;
  // Axis-aligned bounds of the finite primitives (for pictures and the grid).
  Box Bounds() const { return bounds_; }

 private:
  enum Kind : uint32_t { kBox, kCylinder, kSphere, kMedium, kGlass, kMover };
  struct Ref {
    uint32_t kind, index;
    double zlo = 0.0, zhi = 0.0;  // the primitive's vertical extent (culling along the ray)
  };
  Box bounds_;
  double cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> cell_start_;  // CSR: refs of cell c are refs_[cell_start_[c] ...)
  std::vector<double> cell_top_;      // highest point of the refs of cell c
  std::vector<Ref> refs_;
  std::vector<Ref> large_;  // tested once per ray, not binned
  // `time` NaN: the static scene (movers are skipped).
  RayHit IntersectRef(const Ref& r, const Vec3& o, const Vec3& d, const Vec3& inv_d, double t_max,
                      double time) const;
  RayHit CastAt(const Vec3& o, const Vec3& d, double t_max, double time) const;
  RayHit IntersectMedium(uint32_t index, const Vec3& o, const Vec3& d, const Vec3& inv_d,
                         double t_max) const;
  // The ground hit (floors, height fields) with relief and cover applied.
  RayHit CastGround(const Vec3& o, const Vec3& d, double t_max) const;
};

}  // namespace ctlio::sim
