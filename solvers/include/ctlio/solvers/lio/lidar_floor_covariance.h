// A pose covariance whose lidar term has an error floor (window.pose_covariance_lidar_floor_*):
// the point-to-plane residuals of one scan carry independent point noise, which averages out
// over the keypoints, and errors they all share — a rigid misregistration of the whole scan by
// the deskewing's motion error or by the map planes' own error — which does not. The shared part
// is modelled as a rigid error η ~ N(0, Σ_c) of the scan in the robot frame: with H_c the lidar's
// information on the newest pose (body tangent, δ_body of T_mr·Exp(δ_body)) at the point
// variance c·σ², the scan measures the pose with covariance H_c⁻¹ + Σ_c, i.e. information
//   H_f = H_c·(I + Σ_c·H_c)⁻¹                                                          (1)
// (defined for a rank-deficient H_c or Σ_c, PSD; Σ_c = 0 gives H_c). A small c with a floor
// describes a lidar whose translation is better than the configured σ says while its rotation,
// set by the scan's far points and so by the shared angular errors, is not
// (docs/experiments/covariance.md, "Lidar error floor"). Covariance only: the estimate keeps its
// configured σ.
#pragma once

#include <ceres/problem.h>

#include <optional>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// (1) for a 6×6 information H_c and floor covariance Σ_c (both PSD, same tangent).
Mat6 FlooredInformation(const Mat6& H_c, const Mat6& floor);

// The newest pose's covariance (PoseCovariance's convention: ε of T_mr(true) = Exp(ε)·T_mr) from
// the window's dense information (SlidingWindow::Linearize) with the `lidar` blocks' information
// divided by `lidar_scale` (c) and floored by (1) with Σ_c = diag(floor_sigma)² over the body
// tangent [ρ; φ] of `pose`. Needs the lidar blocks on `pose` alone (the IMU-as-input baseline's
// scan state); when they reach other states (the GP knots of a continuous-time scan) the floor is
// not applied and only c is. Empty if the information is not positive definite.
std::optional<Mat6> FlooredLidarPoseCovariance(const SlidingWindow& window, StateId pose,
                                               const std::vector<ceres::ResidualBlockId>& lidar,
                                               double lidar_scale, const Vec6& floor_sigma,
                                               const SE3& T_mr, const Mat6& tangent_from_body);

// The same, carried from scan to scan (window.pose_covariance_lidar_floor_*): the window's
// marginal prior holds the earlier scans' lidar information at the configured σ, so flooring the
// newest scan alone leaves most of a pose's covariance as the estimator's. This recursion keeps
// its own prior instead — the information of the newest scan's states from its own floored
// covariance (the Schur complement onto them of the dense information), which at the next scan
// replaces every residual block whose states are all among them (the window's marginal prior and
// the earlier scan's lidar blocks: their information is in it). A filter's covariance under the
// floored noise model on the window's Jacobians; the estimate is untouched. Starts (and restarts
// when the kept states are not the carried ones, e.g. after a failed scan) from the window's prior.
class FlooredPoseCovariance {
 public:
  // The newest pose's covariance as FlooredLidarPoseCovariance with the carried prior;
  // `newest_states` the states the next scan's prior will be on (Estimator::NewestKeys).
  std::optional<Mat6> Compute(const SlidingWindow& window, StateId pose,
                              const std::vector<StateId>& newest_states,
                              const std::vector<ceres::ResidualBlockId>& lidar, double lidar_scale,
                              const Vec6& floor_sigma, const SE3& T_mr,
                              const Mat6& tangent_from_body);
  // Whether the last Compute used the carried prior (false: the window's).
  bool used_carried_prior() const { return used_carried_; }

 private:
  std::vector<StateId> carried_states_;  // ascending
  Eigen::MatrixXd carried_;              // information over their tangents, in that order
  bool used_carried_ = false;
};

}  // namespace ctlio::lio
