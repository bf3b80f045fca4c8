// The local-geometry statistic of one lidar sweep (docs/experiments/worlds-geometry.md): how much
// of what a sensor sees is flat and how much is scattered, so that simulated worlds can be
// compared with real recordings by the same number.
//
// For one sweep (points in the sensor frame):
//   1. keep the points with range r ∈ [min_range, max_range] (1–60 m);
//   2. voxel-downsample them at `voxel` (0.2 m): one point per occupied voxel, the centroid of
//      its points;
//   3. for every downsampled point take its k = 10 nearest downsampled points (itself included)
//      and the eigenvalues λ1 ≥ λ2 ≥ λ3 ≥ 0 of their covariance
//      Σ = (1/k) Σᵢ (pᵢ − p̄)(pᵢ − p̄)ᵀ;
//   4. "planar" when λ3/λ1 < planar_below (0.01), "scattered" when λ3/λ1 > scattered_above (0.1);
//      the fractions are over the downsampled points; the median range is that of the
//      downsampled points.
// A plane with centimetre noise is planar; a volume of scattered returns (foliage, grass, clutter)
// has λ3 comparable to λ1 and is scattered; edges, poles and corners fall in between.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::eval {

struct GeometryOptions {
  double min_range = 1.0;   // m
  double max_range = 60.0;  // m
  double voxel = 0.2;       // m
  int neighbours = 10;      // k, the point itself included
  double planar_below = 0.01;
  double scattered_above = 0.1;
};

struct GeometryStatistics {
  size_t points = 0;       // in the range gate
  size_t downsampled = 0;  // voxels (= points the fractions are over)
  double planar = 0.0;     // fraction with λ3/λ1 < planar_below
  double scattered = 0.0;  // fraction with λ3/λ1 > scattered_above
  double median_range = 0.0;
  double median_ratio = 0.0;  // median of λ3/λ1 (a finer view than the two fractions)
};

// The statistic of one sweep (sensor-frame points). Throws std::invalid_argument on options out
// of range (min_range < 0, max_range ≤ min_range, voxel ≤ 0, neighbours < 3). Fewer downsampled
// points than `neighbours`: every fraction is 0.
GeometryStatistics ComputeGeometryStatistics(const std::vector<Vec3>& points,
                                             const GeometryOptions& options = {});

// The report's table (ctlio_geometry_report, ctlio_simulate --geometry_report): a header line,
// then one row per sweep: label, points, voxels, planar, scattered, median λ3/λ1, median range.
void WriteGeometryHeader(std::ostream& os);
void WriteGeometryRow(std::ostream& os, const std::string& label, const GeometryStatistics& s);

// Centroids of the occupied voxels of edge `voxel`, in the order of their first point.
std::vector<Vec3> VoxelCentroids(const std::vector<Vec3>& points, double voxel);

// Exact k-nearest-neighbour search in 3-D (a k-d tree over a copy of the points).
class KdTree {
 public:
  explicit KdTree(std::vector<Vec3> points);
  // Indices of the k nearest points to q (fewer if the tree holds fewer), nearest first.
  void Nearest(const Vec3& q, int k, std::vector<int>* indices,
               std::vector<double>* squared_distances = nullptr) const;
  const std::vector<Vec3>& points() const { return points_; }

 private:
  struct Node {
    int point = -1;  // index into points_ (the split point)
    int axis = 0;
    int left = -1, right = -1;
  };
  std::vector<Vec3> points_;
  std::vector<Node> nodes_;
  int root_ = -1;
  int Build(std::vector<int>& order, int lo, int hi, int depth);
};

}  // namespace ctlio::eval
