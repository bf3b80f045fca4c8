// The newest pose's covariance in the one convention every output uses (OdometryConfig
// pose_covariance, ScanResult::pose_covariance): Σ of ε in T_mr(true) = Exp(ε)·T_mr, T_mr the
// robot → map pose, ε = [ρ; φ] translation first (SPEC §1), the error PoseNees evaluates.
#pragma once

#include <ceres/problem.h>

#include <optional>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// ceres::Covariance of the pose block `pose` (PoseManifold, left tangent δ_state) of `problem`
// at its current value, mapped to ε. `tangent_from_body` is A in δ_state = A·δ_body where
// T_mr ← T_mr·Exp(δ_body) (Estimator::NewestPoseTangentFromBody: −I for the GP knots' T_rm,
// Ad(T_wb) for the baseline's T_wb = T_mr). Since T_mr·Exp(δ_body) = Exp(Ad(T_mr)·δ_body)·T_mr,
// ε = Ad(T_mr)·A⁻¹·δ_state. Empty when the window is rank deficient (no pseudo-inverse).
std::optional<Mat6> PoseCovariance(ceres::Problem* problem, const double* pose, const SE3& T_mr,
                                   const Mat6& tangent_from_body);

// The lidar term's own spread, the per-scan χ² scale s = 2·C/N of its residual blocks (C their
// robust cost as Ceres sums it, ½Σρ(r²); N their residual count): 1 when the whitened residuals
// have unit variance, as point_noise_sigma assumes. 1 without residuals.
double LidarChiSquareScale(ceres::Problem* problem,
                           const std::vector<ceres::ResidualBlockId>& lidar);

// As PoseCovariance, from the window's dense Gauss–Newton information (SlidingWindow::Linearize,
// losses as Ceres applies them) with the lidar blocks' information divided by `lidar_scale`
// (their residual variance multiplied by it). Empty if the information is not positive definite.
std::optional<Mat6> ScaledPoseCovariance(const SlidingWindow& window, StateId pose,
                                         const std::vector<ceres::ResidualBlockId>& lidar,
                                         double lidar_scale, const SE3& T_mr,
                                         const Mat6& tangent_from_body);

}  // namespace ctlio::lio
