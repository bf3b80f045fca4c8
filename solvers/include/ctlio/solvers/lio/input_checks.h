// Plausibility gates on the odometry's input (SPEC §5 inputs, SPEC §1 units): data that cannot be
// physical must give a clear warning or error, never a scan reported "ok". Pure functions and a
// small stateful IMU check, independent of the pipelines, so that a runner (or the odometry) can
// apply them before data reach the estimator:
//   * an IMU sample beyond the sensor's physical range (|ω| > max_gyro or |f| > max_accel) is
//     rejected (one 1e30 rad/s sample would otherwise dominate every factor it touches);
//   * an IMU whose output stays bit-identical for `constant_imu_duration` while the lidar moves
//     is dead or frozen (a real MEMS sensor always shows noise);
//   * the mean specific force at initialisation must have the configured gravity's magnitude
//     within `gravity_tolerance` (accelerometer in g, or gyro/accel columns swapped, fail here);
//   * point times before the previous scan's end by more than `scan_time_tolerance` cannot be
//     placed on the trajectory and are dropped (the estimator would clamp them silently).
// The `input:` section of an odometry YAML sets these; data/*.yaml document the keys.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/odometry_config.h"

namespace YAML {
class Node;
}

namespace ctlio::lio {

struct InputCheckOptions {
  double max_gyro = 35.0;              // rad/s (2000 °/s, the usual MEMS full scale)
  double max_accel = 160.0;            // m/s² (16 g)
  double gravity_tolerance = 0.2;      // relative error of |mean specific force| at initialisation
  double constant_imu_duration = 0.5;  // s of bit-identical IMU output that counts as frozen
  double moving_translation = 0.05;    // m between scan ends: "the lidar moves"
  double moving_rotation = 0.02;       // rad between scan ends
  double scan_time_tolerance = 0.01;   // s before the previous scan's end
  // Readers: an IMU gap longer than this is an error (file and line); 0 = off, gaps are warnings
  // and the odometry bridges them (it flags the scans by OdometryConfig::max_imu_gap).
  double max_imu_gap_error = 0.0;  // s

  void Validate() const;  // throws std::invalid_argument naming the field
};

// Reads and removes the optional `input:` section of an odometry YAML root (so that the rest can
// go to OdometryConfigFromYaml). Unknown keys and bad values throw std::runtime_error naming
// `source` and the line.
InputCheckOptions TakeInputCheckOptions(YAML::Node* root, const std::string& source);

// Iteration limits no config may exceed: with zero convergence thresholds the solver runs to them
// on every scan, so an unbounded value means a run that never ends. Throws std::invalid_argument.
void ValidateIterationLimits(const OdometryConfig& config);

// Range check of one sample; the reason when it is rejected.
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

// Removes the points of `scan` timed before `previous_end_ns − tolerance`; returns how many.
size_t DropPointsBefore(int64_t previous_end_ns, int64_t tolerance_ns, LidarScan* scan);

// True when the pose moved by more than the options' thresholds.
bool PoseMoved(const SE3& a, const SE3& b, const InputCheckOptions& options);

}  // namespace ctlio::lio
