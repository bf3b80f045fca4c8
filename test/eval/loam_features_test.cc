// LOAM feature selection (loam_features.h) on synthetic scan lines with known geometry.
#include "loam_features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>

namespace ctlio::icp_pairs {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One line of a lidar at the centre of a square room (walls at ±half): 1800 rays over 360°,
// starting 10° past a corner so that no corner falls in the line's unwindowed ends.
std::vector<Vec3> SquareRoomLine(double half, std::vector<int>* corners) {
  std::vector<Vec3> line;
  const int n = 1800;
  for (int k = 0; k < n; ++k) {
    const double a = kPi / 4 + 10.0 * kPi / 180 + 2 * kPi * k / n;
    const Vec3 d(std::cos(a), std::sin(a), 0.0);
    line.push_back(d * (half / std::max(std::abs(d.x()), std::abs(d.y()))));
  }
  // The rays nearest the corner directions 135°, 225°, 315°, 405°.
  for (int c = 1; c <= 4; ++c) corners->push_back(int(std::lround((c * 90.0 - 10.0) / 0.2)));
  return line;
}

TEST(LoamFeatures, TheCornersAreEdgesAndTheWallsPlanar) {
  std::vector<int> corners;
  const std::vector<Vec3> line = SquareRoomLine(7.9, &corners);
  const LoamFeatures f = SelectLoamFeatures(line, {});
  // Each corner gives one edge (its neighbours along the line are suppressed), at the corner.
  for (const int c : corners) {
    int near = 0;
    for (const size_t e : f.edges) near += std::abs(int(e) - c) <= 5;
    EXPECT_EQ(near, 1) << "corner at ray " << c;
    int sharp = 0;
    for (const size_t e : f.sharp) sharp += std::abs(int(e) - c) <= 1;
    EXPECT_EQ(sharp, 1) << "corner at ray " << c;
  }
  // Nothing else on the flat walls is an edge.
  EXPECT_EQ(f.edges.size(), corners.size());
  // The flat points lie on the walls, away from the corners; 4 per sector at most.
  EXPECT_GE(f.flat.size(), 6u);
  EXPECT_LE(f.flat.size(), 6u * 4u);
  for (const size_t p : f.flat)
    for (const int c : corners) EXPECT_GT(std::abs(int(p) - c), 5) << "flat point " << p;
  // The planar set: the walls thinned to about one point per 0.2 m voxel (4 walls of 15.8 m, off
  // the voxel faces), and never an edge.
  EXPECT_GT(f.planes.size(), 250u);
  EXPECT_LT(f.planes.size(), 400u);
  const std::set<size_t> edges(f.edges.begin(), f.edges.end());
  for (const size_t p : f.planes) EXPECT_EQ(edges.count(p), 0u);
}

TEST(LoamFeatures, EdgesPerSectorAreCappedPerLine) {
  // Two lines of a rough surface: range alternating 5 and 6 m, so every point is sharp and the
  // steps (1 m) are too large for neighbour suppression: only the per-sector caps limit the edges.
  std::vector<Vec3> points;
  std::vector<uint16_t> ring;
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 1200; ++k) {
      const double a = 2 * kPi * k / 1200;
      points.push_back((k % 2 ? 5.0 : 6.0) * Vec3(std::cos(a), std::sin(a), 0.1 * r));
      ring.push_back(uint16_t(r));
    }
  const LoamFeatureOptions o;
  const LoamFeatures f = SelectLoamFeatures(points, ring, o);
  EXPECT_EQ(f.edges.size(), size_t(2 * o.sectors * o.less_sharp_per_sector));
  EXPECT_EQ(f.sharp.size(), size_t(2 * o.sectors * o.sharp_per_sector));
  EXPECT_TRUE(f.flat.empty());
  // Per sector of each line (the sector bounds of loam_features.cc) at most the cap.
  for (int r = 0; r < 2; ++r)
    for (int s = 0; s < o.sectors; ++s) {
      const int w = o.half_window, n = 1200;
      const int begin = r * n + w + (n - 2 * w) * s / o.sectors;
      const int end = r * n + w + (n - 2 * w) * (s + 1) / o.sectors;
      int in = 0;
      for (const size_t e : f.edges) in += int(e) >= begin && int(e) < end;
      EXPECT_EQ(in, o.less_sharp_per_sector) << "line " << r << " sector " << s;
    }
}

TEST(LoamFeatures, MismatchedRingIsAnError) {
  EXPECT_THROW(SelectLoamFeatures(std::vector<Vec3>(20, Vec3::Ones()), {0, 1}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::icp_pairs
