// Ray casting against the worlds' primitives: analytic checks per primitive type (plane, box,
// cylinder, sphere, height field) and the uniform grid against brute force.
#include "ctlio/sim/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ctlio::sim {
namespace {

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

TEST(Geometry, PlanesOfTheScene) {
  Scene s;
  s.floors = {0.0};
  s.ceilings = {3.0};
  s.Build(1.0);
  const Vec3 o(1, 2, 1);
  EXPECT_DOUBLE_EQ(s.Cast(o, Vec3(0, 0, -1), 100).t, 1.0);
  EXPECT_DOUBLE_EQ(s.Cast(o, Vec3(0, 0, 1), 100).t, 2.0);
  const Vec3 d = Vec3(1, 0, -1).normalized();
  const RayHit h = s.Cast(o, d, 100);
  EXPECT_NEAR(h.t, std::sqrt(2.0), 1e-15);
  EXPECT_EQ(h.normal, Vec3(0, 0, 1));
  EXPECT_FALSE(s.Cast(o, Vec3(1, 0, 0), 100).Valid());   // parallel to both
  EXPECT_FALSE(s.Cast(o, Vec3(0, 0, -1), 0.5).Valid());  // beyond t_max
}

TEST(Geometry, BoxEntryFaceAndNormal) {
  const Box b{Vec3(2, -1, 0), Vec3(3, 1, 4)};
  const RayHit h = IntersectBox(b, Vec3(0, 0, 1), Vec3(1, 0, 0), 100);
  EXPECT_DOUBLE_EQ(h.t, 2.0);
  EXPECT_EQ(h.normal, Vec3(-1, 0, 0));
  // Oblique onto the top face.
  const Vec3 d = Vec3(2.5, 0, -2).normalized();
  const RayHit top = IntersectBox(b, Vec3(0, 0, 6), d, 100);
  EXPECT_NEAR(top.t, std::sqrt(2.5 * 2.5 + 4.0), 1e-12);
  EXPECT_EQ(top.normal, Vec3(0, 0, 1));
  EXPECT_FALSE(IntersectBox(b, Vec3(2.5, 0, 1), Vec3(1, 0, 0), 100).Valid());  // from inside
  EXPECT_FALSE(IntersectBox(b, Vec3(0, 2, 1), Vec3(1, 0, 0), 100).Valid());    // passes beside
  EXPECT_FALSE(IntersectBox(b, Vec3(0, 0, 1), Vec3(1, 0, 0), 1.5).Valid());    // beyond t_max
}

TEST(Geometry, CylinderSideAndCaps) {
  const Cylinder c{Vec3(0, 0, 0), 1.0, 5.0};
  RayHit h = IntersectCylinder(c, Vec3(5, 0.5, 2), Vec3(-1, 0, 0), 100);
  EXPECT_NEAR(h.t, 5.0 - std::sqrt(0.75), 1e-12);
  EXPECT_NEAR((h.normal - Vec3(std::sqrt(0.75), 0.5, 0)).norm(), 0.0, 1e-12);
  h = IntersectCylinder(c, Vec3(0.2, 0.1, 10), Vec3(0, 0, -1), 100);
  EXPECT_DOUBLE_EQ(h.t, 5.0);
  EXPECT_EQ(h.normal, Vec3(0, 0, 1));
  EXPECT_FALSE(IntersectCylinder(c, Vec3(5, 0, 6), Vec3(-1, 0, 0), 100).Valid());  // above
  EXPECT_FALSE(IntersectCylinder(c, Vec3(0, 0, 2), Vec3(1, 0, 0), 100).Valid());   // inside
  // Random rays from outside: every hit lies on the side or a cap.
  std::mt19937_64 rng(7);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 o = Vec3(0, 0, 2.5) + 4.0 * RandomUnit(rng);
    const Vec3 d = (Vec3(0, 0, 2.5) + 1.5 * RandomUnit(rng) - o).normalized();
    const RayHit r = IntersectCylinder(c, o, d, 100);
    if (!r.Valid()) continue;
    ++hits;
    const Vec3 p = o + r.t * d;
    const double side = std::abs(p.head<2>().norm() - 1.0), cap = std::min(p.z(), 5.0 - p.z());
    EXPECT_LT(std::min(side, std::abs(cap)), 1e-12);
    EXPECT_GE(p.z(), -1e-12);
    EXPECT_LE(p.z(), 5 + 1e-12);
    EXPECT_LT(r.normal.dot(d), 0.0);  // an entry
  }
  EXPECT_GT(hits, 500);
}

TEST(Geometry, SphereHitsOnTheSurface) {
  const Sphere s{Vec3(1, 2, 3), 1.5};
  EXPECT_DOUBLE_EQ(IntersectSphere(s, Vec3(1, 2, 10), Vec3(0, 0, -1), 100).t, 5.5);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 500; ++i) {
    const Vec3 o = s.centre + 5.0 * RandomUnit(rng);
    const Vec3 d = (s.centre + RandomUnit(rng) - o).normalized();  // aims inside: must hit
    const RayHit h = IntersectSphere(s, o, d, 100);
    ASSERT_TRUE(h.Valid());
    EXPECT_NEAR((o + h.t * d - s.centre).norm(), 1.5, 1e-12);
    EXPECT_NEAR((h.normal - (o + h.t * d - s.centre) / 1.5).norm(), 0.0, 1e-12);
  }
}

HeightField RandomField(std::mt19937_64& rng, double amplitude) {
  HeightField f;
  f.x0 = -20;
  f.y0 = -15;
  f.cell = 1.5;
  f.nx = 30;
  f.ny = 20;
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (int k = 0; k < (f.nx + 1) * (f.ny + 1); ++k) f.z.push_back(u(rng));
  f.UpdateTop();
  return f;
}

TEST(Geometry, HeightFieldFirstHitLiesOnTheBilinearSurface) {
  std::mt19937_64 rng(11);
  const HeightField f = RandomField(rng, 1.0);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 o(std::uniform_real_distribution<double>(-18, 23)(rng),
                 std::uniform_real_distribution<double>(-13, 13)(rng), 1.6);
    Vec3 d = RandomUnit(rng);
    const RayHit h = IntersectHeightField(f, o, d, 200);
    if (!h.Valid()) continue;
    ++hits;
    const Vec3 p = o + h.t * d;
    EXPECT_NEAR(p.z(), f.Height(p.x(), p.y()), 1e-9);
    // The first crossing: the ray stays above the surface before it.
    for (int k = 1; k < 50; ++k) {
      const Vec3 q = o + (h.t * k / 50.0) * d;
      EXPECT_GE(q.z() - f.Height(q.x(), q.y()), -1e-9) << i;
    }
    // Normal: perpendicular to the surface (finite differences of the bilinear patch).
    const double e = 1e-6;
    const Vec3 tx(2 * e, 0, f.Height(p.x() + e, p.y()) - f.Height(p.x() - e, p.y()));
    const Vec3 ty(0, 2 * e, f.Height(p.x(), p.y() + e) - f.Height(p.x(), p.y() - e));
    EXPECT_NEAR(h.normal.dot(tx.normalized()), 0.0, 1e-5);
    EXPECT_NEAR(h.normal.dot(ty.normalized()), 0.0, 1e-5);
  }
  EXPECT_GT(hits, 1000);
}

TEST(Geometry, HeightFieldOfAPlaneEqualsThePlane) {
  HeightField f;
  f.x0 = f.y0 = -50;
  f.cell = 2.0;
  f.nx = f.ny = 50;
  for (int j = 0; j <= f.ny; ++j)
    for (int i = 0; i <= f.nx; ++i) f.z.push_back(0.1 * (f.x0 + 2 * i) - 0.05 * (f.y0 + 2 * j));
  f.UpdateTop();
  const Vec3 n = Vec3(-0.1, 0.05, 1.0).normalized();  // z = 0.1x − 0.05y
  std::mt19937_64 rng(5);
  for (int i = 0; i < 500; ++i) {
    const Vec3 o(0, 0, 2.0);
    Vec3 d = RandomUnit(rng);
    const double t_plane = -(n.dot(o)) / n.dot(d);
    const RayHit h = IntersectHeightField(f, o, d, 200);
    const Vec3 p = o + t_plane * d;
    if (t_plane > 0 && std::abs(p.x()) < 49 && std::abs(p.y()) < 49) {
      ASSERT_TRUE(h.Valid()) << i;
      EXPECT_NEAR(h.t, t_plane, 1e-9 * std::max(1.0, t_plane));
      EXPECT_NEAR((h.normal - n).norm(), 0.0, 1e-12);
    } else if (t_plane <= 0) {
      EXPECT_FALSE(h.Valid());
    }
  }
}

TEST(Geometry, GridTraversalEqualsBruteForce) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-30, 30), size(0.2, 4), z(0, 8);
  Scene s;
  for (int i = 0; i < 60; ++i) {
    const Vec3 c(u(rng), u(rng), z(rng));
    const Vec3 e(size(rng), size(rng), size(rng));
    s.boxes.push_back({c - e / 2, c + e / 2});
    s.cylinders.push_back({Vec3(u(rng), u(rng), z(rng)), size(rng) / 4, size(rng)});
    s.spheres.push_back({Vec3(u(rng), u(rng), z(rng)), size(rng) / 2});
  }
  s.Build(3.0);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    Vec3 o(u(rng), u(rng), z(rng));
    if (s.Occupied(o)) continue;
    const Vec3 d = RandomUnit(rng);
    double best = std::numeric_limits<double>::infinity();
    for (const Box& b : s.boxes) best = std::min(best, IntersectBox(b, o, d, 80).t);
    for (const Cylinder& c : s.cylinders) best = std::min(best, IntersectCylinder(c, o, d, 80).t);
    for (const Sphere& p : s.spheres) best = std::min(best, IntersectSphere(p, o, d, 80).t);
    const RayHit h = s.Cast(o, d, 80);
    EXPECT_EQ(h.t, best) << i;
    hits += h.Valid();
    if (h.Valid()) {
      EXPECT_FALSE(s.Occupied(o + (h.t - 1e-7) * d));  // free just before the hit
      EXPECT_TRUE(s.Occupied(o + (h.t + 1e-7) * d));   // solid just after
    }
  }
  EXPECT_GT(hits, 500);
}

}  // namespace
}  // namespace ctlio::sim
