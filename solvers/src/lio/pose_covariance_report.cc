#include "ctlio/solvers/lio/pose_covariance_report.h"

#include <vector>

#include "ctlio/solvers/lio/pose_covariance.h"

namespace ctlio::lio {
namespace {

// Σ = Σ_rel + Σ_map: the configured map error and the one the map was built with (the latter
// before this scan's insertion is accounted, map_growth_covariance.h (1)).
Mat6 WithMapError(const OdometryConfig& config, const Mat6& relative,
                  PoseCovarianceModels* models) {
  if (config.pose_covariance_map_growth > 0.0) models->growth.Registered(relative);
  return relative + MapCovariance(config) + models->growth.map();
}

}  // namespace

std::optional<Mat6> NewestPoseCovariance(const OdometryConfig& config,
                                         const RegistrationSummary& registered, LidarTerm* term,
                                         const Estimator& estimator,
                                         ceres::ResidualBlockId marginal_prior, const SE3& T_mr,
                                         PoseCovarianceModels* models, SlidingWindow* window) {
  const std::vector<ceres::ResidualBlockId>& lidar = registered.lidar_blocks;
  const StateId pose = estimator.NewestPoseKey();
  const Mat6 tangent_from_body = estimator.NewestPoseTangentFromBody();
  if (config.pose_covariance_adaptive) {
    const ImuTermBlocks& imu = estimator.NewestImuBlocks();
    double lidar_estimate = 0.0;  // no lidar term: nothing to scale
    if (!registered.associated.empty()) {
      // The residuals at the estimate, in metres (the window's are whitened, and a batched
      // term's rows are not per keypoint).
      std::vector<double> e;
      std::vector<Vec3> at;
      term->BeginRound();
      for (size_t i = 0; i < registered.associated.size(); ++i) {
        if (!registered.associated[i]) continue;
        const PlaneAssociation& a = registered.planes[i];
        Vec3 q, p_map;
        term->Locate(i, &q, &p_map);
        e.push_back(a.weight * a.plane_normal.dot(p_map - a.plane_point));
        at.push_back(a.plane_point);
      }
      const LidarSpread spread = MeasureLidarSpread(e, at, kLidarPlaneCell);
      const double sigma = config.frontend.point_noise_sigma;
      lidar_estimate =
          config.pose_covariance_lidar_neff * spread.effective_variance() / (sigma * sigma);
    }
    const std::optional<Mat6> S =
        models->adaptive.Compute(window, pose, lidar_estimate, lidar, imu.accel, imu.gyro,
                                 marginal_prior, T_mr, tangent_from_body);
    if (!S) return std::nullopt;
    return WithMapError(config, *S, models);
  }
  const double scale = config.pose_covariance_lidar_scale;
  const double floor_m = config.pose_covariance_lidar_floor_m;
  const double floor_rad = config.pose_covariance_lidar_floor_rad;
  const std::optional<Mat6> S =
      floor_m > 0.0 || floor_rad > 0.0
          ? models->floored.Compute(
                *window, pose, estimator.NewestKeys(), lidar, scale,
                (Vec6() << floor_m, floor_m, floor_m, floor_rad, floor_rad, floor_rad).finished(),
                T_mr, tangent_from_body)
      : scale == 1.0
          ? PoseCovariance(&window->problem(), window->State(pose), T_mr, tangent_from_body)
          : ScaledPoseCovariance(*window, pose, lidar, scale, T_mr, tangent_from_body);
  if (!S) return std::nullopt;
  return WithMapError(config, *S, models);
}

Mat6 MapCovariance(const OdometryConfig& config) {
  const double t = config.pose_covariance_map_sigma_m, r = config.pose_covariance_map_sigma_rad;
  return (Vec6() << t * t, t * t, t * t, r * r, r * r, r * r).finished().asDiagonal();
}

}  // namespace ctlio::lio
