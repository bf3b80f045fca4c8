// The front end's plane association (SPEC §4): the distance gate, the fit across a ring line,
// the thickness gate, and the voxel planes with their kNN fallback.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"

namespace ctlio::lio {
namespace {

TEST(Frontend, AssociationGate) {
  LidarFrontendOptions options;
  VoxelMap map(LidarFrontend::MapOptions(options));
  // Map: the plane z = 0 sampled every 0.25 m (16 points per voxel, under the bound of 20).
  for (double x = -5; x <= 5; x += 0.25)
    for (double y = -5; y <= 5; y += 0.25) map.Insert(Vec3(x, y, 0.0));
  PlaneAssociator associator(map, options);
  PlaneAssociation a;
  const Vec3 q(1.0, 2.0, 3.0);
  ASSERT_TRUE(associator.Associate(q, Vec3(0.3, 0.2, 0.4), &a));
  EXPECT_NEAR(std::abs(a.plane_normal.z()), 1.0, 1e-9);
  EXPECT_NEAR(a.plane_point.z(), 0.0, 1e-12);
  EXPECT_GT(a.weight, 0.8);
  EXPECT_EQ(a.point_robot, q);
  // 1.2 m above the plane: the ±1 voxel search still finds it, the 1.0 m gate must reject it.
  EXPECT_FALSE(associator.Associate(q, Vec3(0.3, 0.2, 1.2), &a));
  // Far from any map point: too few neighbours.
  EXPECT_FALSE(associator.Associate(q, Vec3(0.3, 0.2, 2.5), &a));
}

// line_neighbourhood_ratio: a VLP-16's map seen from one place is rings on the floor, here two
// arcs of radius 8.0 and 9.3 m (the spacing of neighbouring beams at that range) with ±1 cm
// relief. The 20 nearest points of a point on the inner ring are that ring, a line whose plane
// is noise (planarity weight ≈ 0); fitted across the line, the plane takes in the outer ring and
// is the floor. A ring with no other within reach gives no association; a plane neighbourhood is
// associated as without the option.
TEST(Frontend, LineNeighbourhoodIsFittedAcrossToTheNextRing) {
  LidarFrontendOptions off;
  LidarFrontendOptions on;
  on.line_neighbourhood_ratio = 0.1;
  const auto ring = [](VoxelMap* map, double radius) {
    int n = 0;
    for (double a = -0.4; a <= 0.4; a += 0.1 / radius, ++n) {
      const double relief_z = n % 2 ? 0.01 : -0.01;
      const double relief_r = n % 3 == 0 ? 0.01 : -0.005;
      map->Insert(
          Vec3((radius + relief_r) * std::cos(a), (radius + relief_r) * std::sin(a), relief_z));
    }
  };
  VoxelMap two_rings(LidarFrontend::MapOptions(off));
  ring(&two_rings, 8.0);
  ring(&two_rings, 9.3);
  const Vec3 q(1.0, 2.0, 3.0);
  const Vec3 p(8.0, 0.05, 0.02);
  PlaneAssociation line, across;
  ASSERT_TRUE(PlaneAssociator(two_rings, off).Associate(q, p, &line));
  EXPECT_LT(line.weight, 0.01);
  ASSERT_TRUE(PlaneAssociator(two_rings, on).Associate(q, p, &across));
  EXPECT_GT(std::abs(across.plane_normal.z()), 0.999);
  EXPECT_GT(across.weight, 0.3);
  EXPECT_NEAR(across.plane_point.z(), 0.0, 0.005);
  EXPECT_GT(across.plane_point.x(), 8.1);  // both rings in the fit
  // The outer ring 3 m away (beyond two map voxels): still a line, no association.
  VoxelMap far_rings(LidarFrontend::MapOptions(off));
  ring(&far_rings, 8.0);
  ring(&far_rings, 11.0);
  EXPECT_TRUE(PlaneAssociator(far_rings, off).Associate(q, p, &line));
  EXPECT_FALSE(PlaneAssociator(far_rings, on).Associate(q, p, &across));
  // A plane neighbourhood is no line: the same association with the option as without.
  VoxelMap plane(LidarFrontend::MapOptions(off));
  for (double x = -5; x <= 5; x += 0.25)
    for (double y = -5; y <= 5; y += 0.25) plane.Insert(Vec3(x, y, 0.0));
  const Vec3 r(0.3, 0.2, 0.4);
  ASSERT_TRUE(PlaneAssociator(plane, off).Associate(q, r, &line));
  ASSERT_TRUE(PlaneAssociator(plane, on).Associate(q, r, &across));
  EXPECT_EQ(line.plane_point, across.plane_point);
  EXPECT_EQ(line.plane_normal, across.plane_normal);
  EXPECT_EQ(line.weight, across.weight);
}

// max_plane_thickness: a tree crown is a sphere (here R = 2 m, sampled every 0.1 m and thinned by
// the map as a sweep's points are). The kNN plane through a patch of it is a chord, so a point of
// the surface lies outside that plane (on the side away from the centre, towards the sensor that
// sees it) by about a²/4R: registering a sweep whose points are that surface's own pulls each of
// them inwards. Its planarity weight is of the order of a noisy wall's, so only the thickness σ3
// tells them apart: a gate between the two (a wall with ±1.5 cm of range noise, σ3 ≈ 1.1 cm here;
// the crown patch ≈ 2.6 cm) rejects the crown and leaves the wall's association as it was.
TEST(Frontend, ThickNeighbourhoodIsNoPlane) {
  LidarFrontendOptions off;
  LidarFrontendOptions on;
  on.max_plane_thickness = 0.02;
  const Vec3 q(1.0, 2.0, 3.0);
  // The wall x = 20 seen at range, ±1.5 cm of noise along its normal.
  VoxelMap wall(LidarFrontend::MapOptions(off));
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.015);
  for (double y = -3; y <= 3; y += 0.1)
    for (double z = 0; z <= 6; z += 0.1) wall.Insert(Vec3(20.0 + noise(rng), y, z));
  const Vec3 on_wall(20.0, 0.3, 2.0);
  PlaneAssociation with, without;
  double wall_thickness = -1.0;
  ASSERT_TRUE(PlaneAssociator(wall, off).Associate(q, on_wall, &without, &wall_thickness));
  EXPECT_GT(wall_thickness, 0.005);  // the range noise along the wall's normal, σ 1.5 cm
  EXPECT_LT(wall_thickness, 0.02);
  ASSERT_TRUE(PlaneAssociator(wall, on).Associate(q, on_wall, &with));
  EXPECT_EQ(with.plane_point, without.plane_point);
  EXPECT_EQ(with.weight, without.weight);
  EXPECT_GT(std::abs(with.plane_normal.x()), 0.99);
  // The crown.
  const Vec3 centre(20.0, 0.0, 4.0);
  const double radius = 2.0;
  VoxelMap crown(LidarFrontend::MapOptions(off));
  for (double theta = 0.05; theta < M_PI; theta += 0.1 / radius) {
    const int n = std::max(1, int(std::round(2 * M_PI * radius * std::sin(theta) / 0.1)));
    for (int k = 0; k < n; ++k) {
      const double phi = 2 * M_PI * k / n;
      crown.Insert(centre + radius * Vec3(std::sin(theta) * std::cos(phi),
                                          std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  }
  const Vec3 outward = Vec3(-1.0, 0.2, 0.1).normalized();
  const Vec3 surface = centre + radius * outward;
  PlaneAssociation a;
  double crown_thickness = -1.0;
  ASSERT_TRUE(PlaneAssociator(crown, off).Associate(q, surface, &a, &crown_thickness));
  EXPECT_GT(crown_thickness, 0.02);
  EXPECT_GT(crown_thickness, 2.0 * wall_thickness);
  EXPECT_GT(a.weight, 0.5 * without.weight);
  const double side = a.plane_normal.dot(outward) > 0 ? 1.0 : -1.0;
  const double outside = side * a.plane_normal.dot(surface - a.plane_point);
  EXPECT_GT(outside, 0.02) << "the crown's own point should lie outside its chord plane";
  EXPECT_LT(outside, 0.5);
  EXPECT_FALSE(PlaneAssociator(crown, on).Associate(q, surface, &a));
}

// The voxel-plane association answers from the map's per-voxel plane where the voxel holds
// min_neighbours points, and falls back to the kNN plane where it does not.
TEST(Frontend, VoxelPlaneAssociationAndFallback) {
  LidarFrontendOptions options;
  options.association = "voxel_plane";
  LidarFrontendOptions knn_options;  // association "knn"
  VoxelMap map(LidarFrontend::MapOptions(options));
  ASSERT_TRUE(map.options().fit_planes);
  // The tilted plane z = 0.1·x + 0.05·y with ±1 mm checkerboard relief, every 0.25 m (16 points
  // per voxel) for x < 2; for x in [2, 3) every 0.5 m (4 points per voxel, < min_neighbours).
  const auto z = [](double x, double y) { return 0.1 * x + 0.05 * y; };
  int n = 0;
  for (double x = -5; x < 2.0; x += 0.25)
    for (double y = -5; y <= 5; y += 0.25)
      map.Insert(Vec3(x, y, z(x, y) + (n++ % 2 ? 1e-3 : -1e-3)));
  for (double x = 2.0; x < 3.0; x += 0.5)
    for (double y = -5; y <= 5; y += 0.5) map.Insert(Vec3(x, y, z(x, y)));
  const Vec3 normal = Vec3(-0.1, -0.05, 1.0).normalized();
  PlaneAssociator voxel_planes(map, options);
  PlaneAssociator knn(map, knn_options);
  const Vec3 q(1.0, 2.0, 3.0);
  // Inside a dense voxel: exactly the map's plane of that voxel.
  const Vec3 p(0.3, 0.6, z(0.3, 0.6) + 0.02);
  PlaneAssociation a, b, c;
  ASSERT_TRUE(voxel_planes.Associate(q, p, &a));
  const VoxelPlane* plane = map.PlaneOf(p);
  ASSERT_NE(plane, nullptr);
  EXPECT_GE(plane->points, options.min_neighbours);
  EXPECT_EQ(a.plane_point, plane->fit.centroid);
  EXPECT_EQ(a.plane_normal, plane->fit.normal);
  EXPECT_EQ(a.weight, plane->fit.planarity_weight);
  EXPECT_GT(std::abs(a.plane_normal.dot(normal)), 1.0 - 1e-4);
  EXPECT_NEAR(normal.dot(a.plane_point), 0.0, 1e-3);  // the centroid lies on the plane
  ASSERT_TRUE(knn.Associate(q, p, &b));
  EXPECT_NE(a.plane_point, b.plane_point);  // a different point set: not the kNN plane
  // The same voxel with a thickness limit under its σ3 (~1 mm): the kNN plane instead.
  ASSERT_GT(plane->fit.sigma3, 5e-4);
  LidarFrontendOptions thin = options;
  thin.voxel_plane_max_thickness = 0.5 * plane->fit.sigma3;
  ASSERT_TRUE(PlaneAssociator(map, thin).Associate(q, p, &c));
  EXPECT_EQ(c.plane_point, b.plane_point);
  EXPECT_EQ(c.plane_normal, b.plane_normal);
  // Inside a sparse voxel: the kNN plane, identical to the kNN associator's.
  const Vec3 sparse(2.4, 0.3, z(2.4, 0.3));
  ASSERT_NE(map.PlaneOf(sparse), nullptr);
  EXPECT_LT(map.PlaneOf(sparse)->points, options.min_neighbours);
  ASSERT_TRUE(voxel_planes.Associate(q, sparse, &a));
  ASSERT_TRUE(knn.Associate(q, sparse, &b));
  EXPECT_EQ(a.plane_point, b.plane_point);
  EXPECT_EQ(a.plane_normal, b.plane_normal);
  EXPECT_EQ(a.weight, b.weight);
  // The distance gate applies to the voxel plane too (p is 2 cm off the plane); an empty voxel
  // without neighbours fails.
  LidarFrontendOptions tight = options;
  tight.max_plane_distance = 0.01;
  EXPECT_FALSE(PlaneAssociator(map, tight).Associate(q, p, &a));
  EXPECT_FALSE(voxel_planes.Associate(q, Vec3(0.3, 0.2, 2.5), &a));
  // A voxel_plane associator needs a map that keeps planes.
  VoxelMap plain(VoxelMap::Options{});
  EXPECT_THROW(PlaneAssociator(plain, options), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::lio
