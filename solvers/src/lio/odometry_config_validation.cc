// OdometryConfig::Validate: the ranges and consistency rules every config must meet, however it
// was made (a YAML file, a program's flags, a test). The YAML reader (odometry_config.cc) calls it
// and names the file; the rules themselves live here, one place for every way in.
#include <cmath>
#include <stdexcept>
#include <string>

#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/yaml_io.h"

namespace ctlio::lio {

void OdometryConfig::Validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("OdometryConfig: ") + what);
  };
  frontend.Validate();
  input.Validate();
  require((qc.array() > 0).all(), "gp.qc must be positive on every axis");
  require((alpha.array() >= 0).all(), "gp.alpha must be >= 0 on every axis");
  require(accel_variance > 0 && gyro_variance > 0, "imu variances must be positive");
  require(accel_loss_scale >= 0, "imu.accel_loss_scale must be >= 0");
  // σ of a bias in m/s²: above 10 the gate would open at the start, below 0 never (use 0: off).
  require(accel_loss_relax_bias_sigma >= 0 && accel_loss_relax_bias_sigma <= 10,
          "imu.accel_loss_relax_bias_sigma must be in [0, 10] m/s^2 (0: off)");
  require(accel_loss_relaxed_scale >= 0 && accel_loss_relaxed_scale <= 1e3,
          "imu.accel_loss_relaxed_scale must be in [0, 1000] (0: no loss once relaxed)");
  require(imu_residual_blocks == "sample" || imu_residual_blocks == "interval",
          "imu.residual_blocks must be sample or interval");
  require(gap_prediction_span >= 0 && gap_prediction_span <= 10,
          "window.gap_prediction_span must be in [0, 10] s");
  require(bias_accel_walk > 0 && bias_gyro_walk > 0 && bias_walk_period > 0,
          "bias random walk parameters must be positive");
  require(initial_bias_accel_variance > 0 && initial_bias_gyro_variance > 0,
          "initial bias variances must be positive");
  require(gravity > 0, "imu.gravity must be positive");
  require(input_accel_sigma > 0 && input_gyro_sigma > 0 && imu_rate_hint > 0,
          "imu input noise densities and rate must be positive");
  require(input_interpolation == "linear" || input_interpolation == "cubic",
          "imu.input_interpolation must be linear or cubic");
  require(input_substeps >= 1 && input_substeps <= kMaxInputSubsteps,
          "imu.input_substeps must be in [1, 16]");
  require(input_midpoint || (input_interpolation == "linear" && input_substeps == 1),
          "imu.input_interpolation cubic and imu.input_substeps > 1 need imu.input_midpoint: true "
          "(a held sample has no value between samples to read)");
  // The window becomes nanoseconds before the first scan end (gravity_alignment.cc): 1e30 s
  // overflowed int64 there (UBSan, the bad-input probe), and no real start rests for an hour.
  require(gravity_init_duration >= 0 && gravity_init_duration <= 3600,
          "init.gravity_duration must be in [0, 3600] s");
  require(gravity_init_max_std > 0, "init.gravity_max_std must be positive");
  require(min_associations >= 0, "init.min_associations must be >= 0");
  require(max_imu_gap > 0, "init.max_imu_gap must be positive");
  require(gap_velocity_walk > 0, "imu.gap_velocity_walk must be positive");
  require(gap_hold_max >= 0, "imu.gap_hold_max must be >= 0");
  require(max_scan_translation > 0, "init.max_scan_translation must be positive");
  require(pose_covariance_lidar_scale > 0, "window.pose_covariance_lidar_scale must be positive");
  require(pose_covariance_lidar_neff >= 1.0 && pose_covariance_lidar_neff <= 1e6,
          "window.pose_covariance_lidar_neff must be in [1, 1e6]");
  require(pose_covariance_lidar_floor_m >= 0 && pose_covariance_lidar_floor_m <= 1e3 &&
              pose_covariance_lidar_floor_rad >= 0 && pose_covariance_lidar_floor_rad <= 10,
          "window.pose_covariance_lidar_floor_m must be in [0, 1e3] and "
          "window.pose_covariance_lidar_floor_rad in [0, 10]");
  require(pose_covariance_map_sigma_m >= 0 && pose_covariance_map_sigma_m <= 1e3 &&
              pose_covariance_map_sigma_rad >= 0 && pose_covariance_map_sigma_rad <= 10,
          "window.pose_covariance_map_sigma_m must be in [0, 1e3] and "
          "window.pose_covariance_map_sigma_rad in [0, 10]");
  require(pose_covariance_map_growth >= 0 && pose_covariance_map_growth <= 100,
          "window.pose_covariance_map_growth must be in [0, 100]");
  require(window_knots >= 2 && window_knots <= kMaxWindowKnots,
          "window.knots must be in [2, 1000]");
  require(knots_per_scan >= 1 && knots_per_scan <= 10, "window.knots_per_scan must be in [1, 10]");
  require(adaptive_knots.max_knots_per_scan >= 1 && adaptive_knots.max_knots_per_scan <= 10,
          "window.adaptive_knots_max must be in [1, 10]");
  require(adaptive_knots.gyro_curvature >= 0 && std::isfinite(adaptive_knots.gyro_curvature),
          "window.adaptive_knots_gyro_curvature must be finite and >= 0 (0: not used)");
  require(adaptive_knots.accel_curvature >= 0 && std::isfinite(adaptive_knots.accel_curvature),
          "window.adaptive_knots_accel_curvature must be finite and >= 0 (0: not used)");
  require(adaptive_knots.accel_variance_floor >= 0 &&
              std::isfinite(adaptive_knots.accel_variance_floor) &&
              adaptive_knots.gyro_variance_floor >= 0 &&
              std::isfinite(adaptive_knots.gyro_variance_floor),
          "window.adaptive_knots_accel_variance and _gyro_variance must be finite and >= 0");
  require(adaptive_knots.max_keypoints >= 0 && adaptive_knots.max_keypoints <= 1000000,
          "window.adaptive_knots_max_keypoints must be in [0, 1000000] (0: "
          "lidar_frontend.max_keypoints)");
  slow_sweep_keypoints.Validate();
  require(imus.size() <= 5, "imus: at most 5 IMUs (the bias keys of a knot)");
  for (const ImuSensor& s : imus) {
    require(s.accel_variance >= 0 && s.gyro_variance >= 0, "imus[].variances must be >= 0");
  }
  // (Without `imus` the dataset may still declare them: RunOdometry fills the list.)
  require(input_imu >= 0 && input_imu < (imus.empty() ? 5 : num_imus()),
          "imu.input_imu must index an IMU of imus");
  require(solver_threads >= 1 && solver_threads <= kMaxConfigThreads,
          "window.threads must be in [1, 256]");
  degeneracy.Validate();
  calibration.Validate();
  require(calibration.time_offset_s.empty() ||
              (imus.empty() ? calibration.time_offset_s.size() <= 5
                            : calibration.time_offset_s.size() == imus.size()),
          "calibration.time_offset_s needs one value per IMU of imus");
}

}  // namespace ctlio::lio
