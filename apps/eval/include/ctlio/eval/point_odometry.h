// A small point-to-point lidar odometry in the manner of KISS-ICP (Vizzo et al., RA-L 2023), to
// ask how a method of that kind drifts over a sequence (docs/experiments/worlds-geometry.md):
// constant-velocity prediction and deskewing, a local voxel map with a few points per voxel, an
// adaptive correspondence threshold, registration with point_icp.h.
//
// Sweep k with points p_i at times τ_i [s] relative to the sweep's reference time (its middle):
//   Δ = T_{k−2}⁻¹·T_{k−1} (the last relative motion, one sweep period apart),
//   deskewed p_i' = Exp((τ_i / period)·Log(Δ))·p_i,   prediction T_k⁰ = T_{k−1}·Δ,
// then T_k by Gauss–Newton point-to-point ICP from T_k⁰ against the map, the nearest map point
// among the 27 voxels around each source point within τ = 3σ, Geman–McClure weights of scale
// κ = σ/3 (point_icp.h), σ from AdaptiveThreshold (the prediction's past errors); the map
// takes the deskewed points (one per map_voxel / 2 voxel) at T_k, at most max_points_per_voxel
// per map voxel, and forgets voxels farther than map_radius from the sensor.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "ctlio/manifolds/se3.h"

namespace ctlio::eval {

// KISS-ICP's adaptive threshold (paper, Sec. III-C): the constant-velocity model's error in a
// sweep is bounded by how far its deviation D = T⁰⁻¹·T moves a point at the largest range r_max,
//   δ(D) = |t_D| + 2·r_max·sin(θ_D / 2),
// and σ = √(mean of δ²) over the sweeps whose δ exceeds min_motion (a standstill would otherwise
// shrink σ to nothing), initial_sigma until there is one.
class AdaptiveThreshold {
 public:
  AdaptiveThreshold(double initial_sigma, double min_motion, double max_range)
      : initial_(initial_sigma), min_motion_(min_motion), max_range_(max_range) {}
  // δ(D) above; the deviation is counted when δ > min_motion.
  double Update(const SE3& deviation);
  double Sigma() const;
  int samples() const { return samples_; }

 private:
  double initial_, min_motion_, max_range_;
  double sum_squares_ = 0.0;
  int samples_ = 0;
};

struct PointOdometryOptions {
  double map_voxel = 1.0;     // m (KISS-ICP: max range / 100)
  double source_voxel = 1.5;  // registration points: one per voxel [m] (KISS-ICP: 1.5 voxels)
  int max_points_per_voxel = 20;
  double min_range = 1.0, max_range = 100.0;  // m
  double map_radius = 100.0;                  // m (KISS-ICP: max range)
  bool deskew = true;
  double initial_sigma = 2.0;  // σ before the first counted deviation [m]
  double min_motion = 0.1;     // AdaptiveThreshold's min_motion [m]
  // > 0: a fixed σ (gate 3σ, κ σ/3) instead of the adaptive one (for comparisons only).
  double fixed_sigma = 0.0;
  int iterations = 500;     // ICP iterations at most (KISS-ICP's)
  double converged = 1e-4;  // |δ| that ends the ICP
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
  // σ used for each sweep's registration (0 for the first sweep).
  const std::vector<double>& sigmas() const { return sigmas_; }
  size_t MapSize() const;

 private:
  struct Voxel {
    uint64_t key;
    std::vector<Vec3> points;
  };
  PointOdometryOptions options_;
  SE3 first_, motion_;
  AdaptiveThreshold threshold_;
  std::vector<SE3> poses_;
  std::vector<double> sigmas_;
  std::vector<Voxel> map_;                      // in insertion order (deterministic)
  std::unordered_map<uint64_t, size_t> index_;  // voxel key → map_ index
  void AddToMap(const std::vector<Vec3>& world_points, const Vec3& sensor);
  const Vec3* Nearest(const Vec3& world_point, double max_distance) const;
  SE3 Align(const std::vector<Vec3>& source, const SE3& previous, const SE3& initial,
            double sigma) const;
};

}  // namespace ctlio::eval
