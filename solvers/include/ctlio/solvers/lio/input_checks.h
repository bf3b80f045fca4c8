// Plausibility gates on the odometry's input (SPEC §5 inputs, SPEC §1 units): data that cannot be
// physical must give a clear warning or error, never a scan reported "ok". LioOdometry applies
// them where the data enter, with the thresholds of OdometryConfig::input (input_check_options.h):
//   * ImuBuffer::AddImu: an IMU sample beyond the sensor's physical range (|ω| > max_gyro or
//     |f| > max_accel) or not finite is rejected — not stored, counted, reported in the next
//     ScanResult (one 1e30 rad/s sample would otherwise dominate every factor it touches);
//   * ImuBuffer tracks how long the IMU output has stayed bit-identical; LioOdometry::AddScan,
//     which alone knows whether the lidar moved (the estimate between scan ends), marks a scan
//     kSuspect when the IMU stayed constant for `constant_imu_duration` while it moved: a dead or
//     frozen IMU (a real MEMS sensor always shows noise);
//   * gravity initialisation (InitialiseGravity): the mean specific force over the
//     initialisation window must have the configured gravity's magnitude within
//     `gravity_tolerance` (accelerometer in g, or gyro/accel columns swapped, fail here);
//   * scan preparation: point times outside (previous scan end, this scan end] by more than
//     `scan_time_tolerance` cannot be placed on the trajectory and are dropped and counted
//     (within the tolerance — driver clock jitter — they are clamped onto the interval).
// The iteration limits are part of LidarFrontendOptions::Validate.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/input_check_options.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// Range check of one sample (non-finite values included); the reason when it is rejected.
std::optional<std::string> CheckImuRange(const ImuSample& sample, const InputCheckOptions& options);

// Tracks how long the IMU output has been bit-identical.
class ConstantImuDetector {
 public:
  void Add(const ImuSample& sample);
  double ConstantSeconds() const;  // duration of the current run of identical samples

 private:
  bool have_ = false;
  ImuSample first_, last_;
};

// |mean specific force| of `samples` against `gravity`; the message when the relative error
// exceeds `tolerance` (or there are no samples).
std::optional<std::string> CheckGravityMagnitude(const std::vector<ImuSample>& samples,
                                                 double gravity, double tolerance);

// Removes the points of `scan` timed outside [lo_ns, hi_ns] (order kept); returns how many.
size_t DropPointsOutside(int64_t lo_ns, int64_t hi_ns, LidarScan* scan);

// True when the pose moved by more than the options' thresholds.
bool PoseMoved(const SE3& a, const SE3& b, const InputCheckOptions& options);

}  // namespace ctlio::lio
