// The pose covariance's honesty about model misfit (window.pose_covariance_misfit): where a
// sweep's own IMU residuals say the motion model did not fit, the newest pose's covariance grows
// by what that model's information on the sweep was worth. Covariance only: the estimate is
// unchanged. docs/experiments/covariance.md, "Model misfit".
//
// The IMU terms of the newest interval (Singer-LIO: accelerometer and gyro samples; the baseline:
// its preintegrated factor) are whitened by their configured σ, which already allows for the
// motion model's interpolation error (e.g. 5× the device's σ). A sensor's reduced χ², χ²/dof, is
// then the a-posteriori variance factor of what it tests: the global test of adjustment theory
// rejects the model where χ² exceeds its 99.9 % quantile (and χ²/dof > 1), and the factor says
// by how much the stated variance was too small. The accelerometer tests the translational
// motion model of the interval: every term on the newest states but the lidar's, the marginal
// prior and the gyro's — its own terms, the motion prior between the knots (the GP prior or the
// preintegration's) and the bias walk. Where it is rejected, that information is divided by
// f = χ²/dof (variance-component estimation with the accelerometer's residuals as the group's),
// and the covariance gains the difference
//   Δ = Σ(H_o + H_m/f) − Σ(H_o + H_m)  ⪰ 0,                                                 (1)
// H_m the released information, H_o the rest of the window (the lidar at the covariance's lidar
// scale). The motion prior also holds rotation, which the gyro tests on its own: of (1) the
// translation block is kept, and a rejected gyro adds the rotation block of its own release
// (the baseline's one factor of both sensors adds the whole Δ). A muted measurement (a robust
// loss already down-weights an accelerometer that steps) changes little; the motion prior that
// held the pose is what (1) releases. With the map's error as built (map_growth_covariance.h) Δ
// enters Σ_rel, so the map's error carries it.
#pragma once

#include <ceres/problem.h>

#include <optional>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/lio/adaptive_covariance.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// The variance factor f of (1): χ²/dof where χ² exceeds its 0.999 quantile (ChiSquareQuantile,
// chi_square.h) and χ²/dof > 1; else 1 (also for dof ≤ 0 or a non-finite χ²).
double MisfitFactor(double chi2, int dof);

// The newest interval's motion-model blocks: every residual block on `newest` states except
// `lidar`'s and `prior`.
std::vector<ceres::ResidualBlockId> MotionModelBlocks(
    const SlidingWindow& window, const std::vector<StateId>& newest,
    const std::vector<ceres::ResidualBlockId>& lidar, ceres::ResidualBlockId prior);

// Δ of (1) for the pose `pose` (ε convention of PoseCovariance): the window's dense information
// with `lidar` at `lidar_scale` and each group of `released` divided by its scale, against the
// same with those groups at 1. Empty when either information is not positive definite; zero
// when no group's scale exceeds 1.
std::optional<Mat6> MisfitCovarianceIncrease(const SlidingWindow& window, StateId pose,
                                             const std::vector<ceres::ResidualBlockId>& lidar,
                                             double lidar_scale,
                                             const std::vector<ScaledGroup>& released,
                                             const SE3& T_mr, const Mat6& tangent_from_body);

}  // namespace ctlio::lio
