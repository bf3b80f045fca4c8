// The --save_map accumulator (apps/lio/map_accumulator.h): one point per voxel at the centroid of
// its points, scans merging in the same voxels, voxel boundaries on negative coordinates, the
// max_points cap and its memory bound, bad input.
#include "lio/map_accumulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

namespace ctlio::lioapp {
namespace {

using Key = std::tuple<long, long, long>;
Key VoxelOf(const Vec3& p, double size) {
  return {std::lround(std::floor(p.x() / size)), std::lround(std::floor(p.y() / size)),
          std::lround(std::floor(p.z() / size))};
}

TEST(MapAccumulator, OnePointPerVoxelAtTheCentroid) {
  MapAccumulator map(0.5);
  // Three points in voxel (0, 0, 0), one in (−1, 0, 0): −0.01 lies left of the boundary at 0.
  map.Add({Vec3(0.1, 0.1, 0.1), Vec3(0.2, 0.4, 0.3), Vec3(0.45, 0.01, 0.2), Vec3(-0.01, 0.2, 0.2)});
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map.added_points(), 4u);
  std::vector<Vec3> points = map.Points();
  std::sort(points.begin(), points.end(),
            [](const Vec3& a, const Vec3& b) { return a.x() < b.x(); });
  EXPECT_LT((points[0] - Vec3(-0.01, 0.2, 0.2)).norm(), 1e-6);
  EXPECT_LT((points[1] - Vec3(0.75 / 3, 0.51 / 3, 0.6 / 3)).norm(), 1e-6);
}

TEST(MapAccumulator, TwoScansMergeInTheirCommonVoxels) {
  // Two scans of one wall (x = 2), the second seen from a pose 1 m further along y: in the
  // output frame they overlap on y ∈ [1, 3), so the map is the union of their voxels, and a
  // voxel both saw holds the centroid of both scans' points.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 3.0);
  std::vector<Vec3> a, b;
  for (int i = 0; i < 2000; ++i) a.emplace_back(2.05, u(rng), u(rng));
  for (int i = 0; i < 2000; ++i) b.emplace_back(2.05, u(rng), u(rng));
  const SE3 T(Mat3::Identity(), Vec3(0, 1, 0));  // b's frame → output frame
  const double size = 0.25;
  MapAccumulator map(size);
  map.Add(a);
  const size_t after_a = map.size();
  map.Add(b, T);
  std::map<Key, std::pair<Vec3, int>> expected;  // sum and count per voxel
  const auto add = [&](const Vec3& p) {
    auto& e = expected.try_emplace(VoxelOf(p, size), Vec3::Zero(), 0).first->second;
    e.first += p;
    ++e.second;
  };
  for (const Vec3& p : a) add(p);
  for (const Vec3& q : b) add(T * q);
  EXPECT_EQ(after_a, 12u * 12u);     // 3 m × 3 m of wall in 0.25 m voxels
  EXPECT_EQ(map.size(), 16u * 12u);  // y ∈ [0, 4): the overlap was merged, not doubled
  ASSERT_EQ(map.size(), expected.size());
  for (const Vec3& p : map.Points()) {
    const auto it = expected.find(VoxelOf(p, size));
    ASSERT_NE(it, expected.end()) << p.transpose();
    EXPECT_LT((p - it->second.first / it->second.second).norm(), 1e-5);
  }
}

TEST(MapAccumulator, GrowsWithoutLosingVoxels) {
  // 100 000 distinct voxels over ±1 km (many table doublings, negative indices): every one
  // comes back, at its point.
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> v(-10000, 10000);
  std::map<Key, Vec3> expected;
  std::vector<Vec3> points;
  while (expected.size() < 100000) {
    const Vec3 p(0.1 * v(rng) + 0.05, 0.1 * v(rng) + 0.03, 0.1 * v(rng) + 0.07);
    if (expected.emplace(VoxelOf(p, 0.1), p).second) points.push_back(p);
  }
  MapAccumulator map(0.1);
  map.Add(points);
  ASSERT_EQ(map.size(), expected.size());
  for (const Vec3& p : map.Points()) {
    const auto it = expected.find(VoxelOf(p, 0.1));
    ASSERT_NE(it, expected.end());
    EXPECT_LT((p - it->second).norm(), 1e-4);
  }
  // Load ≤ 0.7 in a power of two of 24-byte slots: 2^18 slots for 100 000 points.
  EXPECT_EQ(map.bytes(), (size_t{1} << 18) * 24);
  EXPECT_EQ(map.peak_bytes(), map.bytes() * 3 / 2);  // the last doubling: old + new table
}

TEST(MapAccumulator, MaxPointsBoundsTheMapAndItsMemory) {
  const size_t cap = 5000;
  MapAccumulator map(0.2, cap);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::vector<Vec3> scan(1000);
  for (int k = 0; k < 50; ++k) {  // 50 000 points in ~10^9 voxels: nearly all new
    for (Vec3& p : scan) p = Vec3(u(rng), u(rng), u(rng));
    map.Add(scan);
  }
  EXPECT_EQ(map.size(), cap);
  EXPECT_EQ(map.added_points(), 50000u);
  EXPECT_NEAR(double(map.dropped_points()), 45000.0, 10.0);
  // The documented bound, 24 B × next_pow2(cap / 0.7) × 1.5: 8192 slots.
  EXPECT_LE(map.peak_bytes(), size_t(24 * 8192 * 3 / 2));
  // An occupied voxel keeps averaging after the cap: its point moves, no voxel is added.
  const Vec3 first = map.Points().front();
  const Vec3 centre = (first / 0.2).array().floor().matrix() * 0.2 + Vec3::Constant(0.1);
  map.Add({centre + (centre - first)});  // the mirror image about the voxel centre
  EXPECT_EQ(map.size(), cap);
  bool moved = false;
  for (const Vec3& p : map.Points()) moved |= (p - first).norm() < 1e-9;
  EXPECT_FALSE(moved);  // no point is where `first` was any more
}

TEST(MapAccumulator, ClearStartsOver) {
  MapAccumulator map(0.5);
  map.Add({Vec3(0.1, 0.1, 0.1), Vec3(3, 3, 3)});
  map.Clear();
  EXPECT_EQ(map.size(), 0u);
  EXPECT_TRUE(map.Points().empty());
  map.Add({Vec3(0.3, 0.2, 0.1)});  // the old centroid of its voxel does not come back
  ASSERT_EQ(map.size(), 1u);
  EXPECT_LT((map.Points()[0] - Vec3(0.3, 0.2, 0.1)).norm(), 1e-6);
  EXPECT_EQ(map.added_points(), 1u);
}

TEST(MapAccumulator, BadInput) {
  EXPECT_THROW(MapAccumulator{0.0}, std::invalid_argument);
  EXPECT_THROW(MapAccumulator{-0.2}, std::invalid_argument);
  EXPECT_THROW(MapAccumulator{std::numeric_limits<double>::quiet_NaN()}, std::invalid_argument);
  MapAccumulator map(0.2);
  // Not finite, or beyond the key range (2^20 voxels of 0.2 m ≈ 210 km): dropped and counted.
  map.Add({Vec3(NAN, 0, 0), Vec3(0, std::numeric_limits<double>::infinity(), 0), Vec3(0, 0, 3.0e5),
           Vec3(1, 1, 1)});
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.out_of_range_points(), 3u);
}

}  // namespace
}  // namespace ctlio::lioapp
