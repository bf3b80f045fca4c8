// Online lidar–IMU calibration in Singer-LIO and lidar_gyro (top-level YAML section
// `calibration:`): a constant clock offset per IMU and the extrinsic T_imu_lidar as static states
// of the window, each with a Gaussian prior centred on the configured value, kept (with the
// marginal prior's information) when knots leave. Off by default: then no such state exists and
// the estimator is the one without calibration, bit for bit.
//
// Time offset: IMU j's sample stamped t on its own clock measures the state at τ = t + δ_j on the
// lidar clock (the state's time line); δ_j > 0 means the IMU's stamps are late.
#pragma once

#include <cstddef>
#include <vector>

namespace ctlio::lio {

struct CalibrationOptions {
  bool estimate_time_offset = false;
  // δ_j per IMU [s]: initial value and prior mean (empty = 0 for every IMU; otherwise one per IMU).
  // Also applied, unestimated, when estimate_time_offset is off and the list is not all zero.
  std::vector<double> time_offset_s;
  double time_offset_prior_sigma_s = 0.03;  // σ of the prior on δ_j

  bool estimate_extrinsic = false;         // T_imu_lidar (OdometryConfig::T_imu_lidar the mean)
  double extrinsic_prior_sigma_deg = 5.0;  // σ of the prior per rotation axis
  double extrinsic_prior_sigma_m = 0.2;    // σ of the prior per translation axis

  // δ_j's configured value (0 when the list is empty).
  double TimeOffset(int j) const {
    return time_offset_s.empty() ? 0.0 : time_offset_s[static_cast<std::size_t>(j)];
  }
  bool any() const { return estimate_time_offset || estimate_extrinsic; }

  void Validate() const;  // throws std::invalid_argument naming the field
};

}  // namespace ctlio::lio
