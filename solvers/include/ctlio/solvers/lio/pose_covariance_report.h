// The newest pose's covariance for the scan's report (OdometryConfig::pose_covariance, ε of
// pose_covariance.h): which noise model it takes, from the registered scan and the window. Not a
// step of the odometry's estimate (the estimate is final when it runs): LioOdometry::Process calls
// it after the registration.
//
// window.pose_covariance_adaptive: each scan's lidar variance from the robust spread of its
// point-to-plane residuals and the IMU groups' levels by variance components
// (adaptive_covariance.h). Else, with window.pose_covariance_lidar_floor_m/_rad, the lidar's
// point noise plus a rigid per-scan error carried from scan to scan (lidar_floor_covariance.h);
// else the window as solved (pose_covariance_lidar_scale 1), or with the lidar blocks' variance
// multiplied by that scale. Each adds the map's own error
// (window.pose_covariance_map_sigma_m/_rad, and the map's error as it was built,
// window.pose_covariance_map_growth: map_growth_covariance.h); with window.pose_covariance_misfit,
// the relative part grows where the scan's IMU χ² rejects the motion model
// (misfit_covariance.h). Not the lidar term's plain χ²
// (LidarChiSquareScale): its spread alone made the baseline 40× overconfident
// (docs/experiments/covariance.md).
#pragma once

#include <optional>

#include "ctlio/solvers/lio/adaptive_covariance.h"
#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/lidar_floor_covariance.h"
#include "ctlio/solvers/lio/map_growth_covariance.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// The noise models' state across scans.
struct PoseCovarianceModels {
  AdaptiveNoiseScales adaptive;   // window.pose_covariance_adaptive
  FlooredPoseCovariance floored;  // window.pose_covariance_lidar_floor_*
  MapGrowthCovariance growth;     // window.pose_covariance_map_growth
};

// Σ_map of OdometryConfig::pose_covariance_map_sigma_m/_rad: a rigid map error Exp(m) adds Cov(m)
// to a left perturbation in the map frame (ε convention).
Mat6 MapCovariance(const OdometryConfig& config);

// Σ of the estimator's newest pose (T_mr = `T_mr`); empty when the window is rank deficient.
// `term`: the scan's lidar term (its residuals at the estimate, adaptive model only);
// `marginal_prior`: the window's marginalisation prior (MarginalizationReport::prior);
// `models`: the noise models' state across scans.
std::optional<Mat6> NewestPoseCovariance(const OdometryConfig& config,
                                         const RegistrationSummary& registered, LidarTerm* term,
                                         const Estimator& estimator,
                                         ceres::ResidualBlockId marginal_prior, const SE3& T_mr,
                                         PoseCovarianceModels* models, SlidingWindow* window);

}  // namespace ctlio::lio
