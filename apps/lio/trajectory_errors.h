// The estimate against the ground truth: ATE after SE(3) alignment, drift per distance, and the
// per-pose errors the plots read. Shared by ctlio_odometry and ctlio_experiment (run_odometry.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lioapp {

// The window of the drift figure [m] (RunSummary::drift_per_100m).
inline constexpr double kDriftWindow = 10.0;

struct AteResult {
  double rmse = 0.0;  // m, after SE(3) Umeyama alignment
  double mean = 0.0;
  double max = 0.0;
  size_t pairs = 0;
  Eigen::Matrix4d alignment = Eigen::Matrix4d::Identity();  // estimate → truth frame
};

// ATE of `estimate` against `truth` (time association within 1 ms; truth interpolated between
// its two nearest poses), SE(3) Umeyama alignment.
AteResult EvaluateAte(const std::vector<io::StampedPose>& estimate,
                      const std::vector<io::StampedPose>& truth);

// RunSummary::drift_per_100m of `estimate` against `truth` (nullopt: path < 1 m).
std::optional<double> DriftPer100m(const std::vector<io::StampedPose>& estimate,
                                   const std::vector<io::StampedPose>& truth);

// Per-pose errors against the truth after `alignment` (estimate → truth frame), CSV:
// t_s, aligned estimate x y z, truth x y z, position error [m], rotation error [deg]: the angle of
// the rotation drift since the first pose, (C_t0ᵀ C_t)ᵀ (C_e0ᵀ C_e), with the truth rotation of the
// nearest truth pose. Poses outside the truth are left out. Read by tools/plot_odometry.py.
void WritePoseErrors(const std::string& path, const std::vector<io::StampedPose>& estimate,
                     const std::vector<io::StampedPose>& truth, const Eigen::Matrix4d& alignment);

// NEES of the scans' pose covariances against the truth T_world_lidar (RunSummary::nees…), the
// map frame anchored at the first estimated scan (where the estimate is the identity, held
// constant); failed scans, scans without a truth pose within 1 ms or without a covariance are
// left out.
struct PoseNees {
  std::vector<double> pose, translation, rotation;
  // Per axis of ε = [ρ; φ]: the scans whose error lies within ±3σ of that axis (of pose.size()).
  std::array<size_t, 6> inside_3sigma{};
};
PoseNees EvaluatePoseNees(const std::vector<lio::ScanResult>& scans,
                          const std::vector<io::StampedPose>& truth, const SE3& T_imu_lidar);

}  // namespace ctlio::lioapp
