// The local-geometry statistic (apps/eval geometry_statistics.h) on clouds with known answers.
#include "ctlio/eval/geometry_statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace ctlio::eval {
namespace {

TEST(GeometryStatistics, KdTreeFindsTheSameNeighboursAsBruteForce) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  std::vector<Vec3> points(2000);
  for (Vec3& p : points) p = Vec3(u(rng), u(rng), 0.1 * u(rng));
  const KdTree tree(points);
  std::vector<int> nn;
  std::vector<double> d2;
  for (int q = 0; q < 200; ++q) {
    const Vec3 x(u(rng), u(rng), u(rng));
    tree.Nearest(x, 10, &nn, &d2);
    std::vector<double> all;
    for (const Vec3& p : points) all.push_back((p - x).squaredNorm());
    std::sort(all.begin(), all.end());
    ASSERT_EQ(nn.size(), 10u);
    for (int k = 0; k < 10; ++k) {
      EXPECT_DOUBLE_EQ(d2[k], all[k]);
      EXPECT_DOUBLE_EQ((tree.points()[nn[k]] - x).squaredNorm(), all[k]);
    }
  }
  tree.Nearest(Vec3::Zero(), 5000, &nn);  // more than it holds: all of them
  EXPECT_EQ(nn.size(), points.size());
}

TEST(GeometryStatistics, VoxelCentroidsAverageThePointsOfAVoxel) {
  const std::vector<Vec3> points = {Vec3(0.01, 0.01, 0.01), Vec3(0.19, 0.11, 0.05),
                                    Vec3(0.21, 0.0, 0.0), Vec3(-0.01, 0.0, 0.0)};
  const std::vector<Vec3> c = VoxelCentroids(points, 0.2);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_TRUE(c[0].isApprox(Vec3(0.1, 0.06, 0.03)));
  EXPECT_TRUE(c[1].isApprox(points[2]));
  EXPECT_TRUE(c[2].isApprox(points[3]));
}

TEST(GeometryStatistics, APlaneIsPlanarAndABlobIsScattered) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::uniform_real_distribution<double> u(0, 1);
  // A tilted plane 2 m below the sensor with 2 mm noise, sampled at random.
  std::vector<Vec3> plane;
  for (int k = 0; k < 40000; ++k) {
    const double x = -15 + 30 * u(rng), y = -15 + 30 * u(rng);
    plane.push_back(Vec3(x, y, -2.0 + 0.1 * x + noise(rng)));
  }
  const GeometryStatistics a = ComputeGeometryStatistics(plane);
  EXPECT_GT(a.planar, 0.95);
  EXPECT_LT(a.scattered, 0.01);
  EXPECT_GT(a.downsampled, 10000u);
  // Points scattered uniformly in a 4 m cube 10 m away, sparser than the voxels (every point
  // its own voxel): isotropic neighbourhoods.
  std::vector<Vec3> blob;
  for (int k = 0; k < 3000; ++k) blob.push_back(Vec3(8 + 4 * u(rng), -2 + 4 * u(rng), 4 * u(rng)));
  const GeometryStatistics b = ComputeGeometryStatistics(blob);
  EXPECT_GT(b.scattered, 0.85);
  EXPECT_LT(b.planar, 0.01);
  EXPECT_NEAR(b.median_range, 10.4, 0.6);
}

TEST(GeometryStatistics, RangeGateAndOptions) {
  std::vector<Vec3> points = {Vec3(0.5, 0, 0), Vec3(70, 0, 0)};
  for (int k = 0; k < 20; ++k) points.push_back(Vec3(5 + 0.3 * k, 0.05 * (k % 3), 0.02 * (k % 2)));
  const GeometryStatistics s = ComputeGeometryStatistics(points);
  EXPECT_EQ(s.points, 20u);  // 0.5 m and 70 m are outside 1–60 m
  GeometryOptions bad;
  bad.voxel = 0.0;
  EXPECT_THROW(ComputeGeometryStatistics(points, bad), std::invalid_argument);
  bad = GeometryOptions();
  bad.max_range = 0.5;
  EXPECT_THROW(ComputeGeometryStatistics(points, bad), std::invalid_argument);
  // Fewer points than neighbours: nothing to classify.
  const GeometryStatistics few = ComputeGeometryStatistics({Vec3(3, 0, 0), Vec3(4, 0, 0)});
  EXPECT_EQ(few.downsampled, 2u);
  EXPECT_EQ(few.planar + few.scattered, 0.0);
}

}  // namespace
}  // namespace ctlio::eval
