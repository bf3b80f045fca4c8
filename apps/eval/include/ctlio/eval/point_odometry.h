// A small point-to-point lidar odometry in the manner of KISS-ICP (Vizzo et al., RA-L 2023), to
// ask how a method of that kind drifts over a sequence (docs/experiments/worlds-geometry.md):
// constant-velocity prediction and deskewing, a local voxel map with a few points per voxel,
// registration with point_icp.h.
//
// Sweep k with points p_i at times τ_i [s] relative to the sweep's reference time (its middle):
//   Δ = T_{k−2}⁻¹·T_{k−1} (the last relative motion, one sweep period apart),
//   deskewed p_i' = Exp((τ_i / period)·Log(Δ))·p_i,   prediction T_k⁰ = T_{k−1}·Δ,
// then T_k = RegisterPointToPoint(source, map, T_k⁰); the map takes the deskewed points (one per
// map_voxel / 2 voxel) at T_k, at most max_points_per_voxel per map voxel, and forgets voxels
// farther than map_radius from the sensor.
#pragma once

#include <vector>

#include "ctlio/eval/point_icp.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio::eval {

struct PointOdometryOptions {
  double map_voxel = 1.0;     // m (KISS-ICP: max range / 100)
  double source_voxel = 1.5;  // registration points: one per voxel [m]
  int max_points_per_voxel = 20;
  double min_range = 1.0, max_range = 100.0;  // m
  double map_radius = 100.0;                  // m
  bool deskew = true;
  std::vector<double> gates = {2.0, 1.0, 0.5};  // m
  double damping = 0.1;                         // PointIcpOptions::damping
};

class PointOdometry {
 public:
  // The first sweep's pose is `first` (T_world_lidar at its reference time); `motion` the
  // relative motion per sweep assumed until two sweeps are registered (a start in motion).
  explicit PointOdometry(const SE3& first = SE3(), const PointOdometryOptions& options = {},
                         const SE3& motion = SE3());

  // Registers the next sweep (lidar frame; `times` as above, one per point; `period` the sweep
  // period [s]) and returns its pose T_world_lidar. Throws std::invalid_argument when the sizes
  // differ or the period is not positive.
  SE3 Register(const std::vector<Vec3>& points, const std::vector<double>& times, double period);

  const std::vector<SE3>& poses() const { return poses_; }
  size_t MapSize() const;

 private:
  struct Voxel {
    std::vector<Vec3> points;
  };
  PointOdometryOptions options_;
  SE3 first_, motion_;
  std::vector<SE3> poses_;
  std::vector<std::pair<uint64_t, Voxel>> map_;  // in insertion order (deterministic)
  void AddToMap(const std::vector<Vec3>& world_points, const Vec3& sensor);
};

}  // namespace ctlio::eval
