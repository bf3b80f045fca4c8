#include "ctlio/solvers/lio/pose_covariance_report.h"

#include <algorithm>
#include <set>
#include <vector>

#include "ctlio/solvers/lio/imu_consistency.h"
#include "ctlio/solvers/lio/misfit_covariance.h"
#include "ctlio/solvers/lio/pose_covariance.h"

namespace ctlio::lio {
namespace {

// With window.pose_covariance_misfit, Σ_rel plus what the newest interval's motion model was
// worth where its IMU residuals reject it (misfit_covariance.h (1)); then Σ = Σ_rel + Σ_map: the
// configured map error and the one the map was built with (the latter before this scan's
// insertion is accounted, map_growth_covariance.h (1)).
std::optional<Mat6> WithMisfitAndMapError(const OdometryConfig& config, const Mat6& window_only,
                                          double lidar_scale, const RegistrationSummary& registered,
                                          const Estimator& estimator,
                                          ceres::ResidualBlockId marginal_prior, const SE3& T_mr,
                                          PoseCovarianceModels* models, SlidingWindow* window) {
  Mat6 relative = window_only;
  if (config.pose_covariance_misfit) {
    // Each sensor by its own test (misfit_covariance.h). With a gyro χ² of its own (Singer-LIO)
    // the accelerometer tests the translational motion model: its rejection releases the motion
    // prior and the bias walk with it, of which the translation block is kept; the gyro tests
    // the rotation (its blocks, or with interval batches the same blocks, whose rotation block
    // is kept). One factor of both sensors (the baseline's preintegration, no gyro χ² of its
    // own) releases the whole increase.
    const ImuTermBlocks& imu = estimator.NewestImuBlocks();
    ChiSquare accel, gyro;
    EvaluateImuChiSquare(&window->problem(), imu, &accel, &gyro);
    const double f_accel = MisfitFactor(accel.chi2, accel.dof);
    const double f_gyro = MisfitFactor(gyro.chi2, gyro.dof);
    if (f_accel > 1.0 || f_gyro > 1.0) {
      std::vector<ceres::ResidualBlockId> motion = MotionModelBlocks(
          *window, estimator.NewestKeys(), registered.lidar_blocks, marginal_prior);
      const std::set<ceres::ResidualBlockId> gyro_blocks(imu.gyro.begin(), imu.gyro.end());
      motion.erase(std::remove_if(motion.begin(), motion.end(),
                                  [&](ceres::ResidualBlockId r) { return gyro_blocks.count(r); }),
                   motion.end());
      const auto increase = [&](const std::vector<ceres::ResidualBlockId>& blocks, double f) {
        return MisfitCovarianceIncrease(*window, estimator.NewestPoseKey(), registered.lidar_blocks,
                                        lidar_scale, {ScaledGroup{blocks, f}}, T_mr,
                                        estimator.NewestPoseTangentFromBody());
      };
      const std::optional<Mat6> d_accel = increase(motion, f_accel);
      if (!d_accel) return std::nullopt;
      if (gyro.dof == 0) {
        relative += *d_accel;
      } else {
        const std::optional<Mat6> d_gyro = increase(imu.gyro.empty() ? motion : imu.gyro, f_gyro);
        if (!d_gyro) return std::nullopt;
        relative.topLeftCorner<3, 3>() += d_accel->topLeftCorner<3, 3>();
        relative.bottomRightCorner<3, 3>() += d_gyro->bottomRightCorner<3, 3>();
      }
    }
  }
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
      std::vector<double> e, sigma;
      std::vector<Vec3> at;
      term->BeginRound();
      for (size_t i = 0; i < registered.associated.size(); ++i) {
        if (!registered.associated[i]) continue;
        const PlaneAssociation& a = registered.planes[i];
        Vec3 q, p_map;
        term->Locate(i, &q, &p_map);
        e.push_back(a.weight * a.plane_normal.dot(p_map - a.plane_point));
        sigma.push_back(registered.noise_sigma[i]);
        at.push_back(a.plane_point);
      }
      lidar_estimate = LidarVarianceFactor(e, sigma, at, config.pose_covariance_lidar_neff);
    }
    const std::optional<Mat6> S =
        models->adaptive.Compute(window, pose, lidar_estimate, lidar, imu.accel, imu.gyro,
                                 marginal_prior, T_mr, tangent_from_body);
    if (!S) return std::nullopt;
    return WithMisfitAndMapError(config, *S, models->adaptive.lidar(), registered, estimator,
                                 marginal_prior, T_mr, models, window);
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
  return WithMisfitAndMapError(config, *S, scale, registered, estimator, marginal_prior, T_mr,
                               models, window);
}

Mat6 MapCovariance(const OdometryConfig& config) {
  const double t = config.pose_covariance_map_sigma_m, r = config.pose_covariance_map_sigma_rad;
  return (Vec6() << t * t, t * t, t * t, r * r, r * r, r * r).finished().asDiagonal();
}

}  // namespace ctlio::lio
