// A GP method's scan that no IMU sample measures: every lidar_only scan, and a Singer-LIO or
// lidar_gyro scan inside an IMU outage (docs/experiments/imu-dropout.md). Only the lidar moves its
// states away from the prior's prediction, so such a scan
// - is registered with its own, larger budget (LidarFrontendOptions::max_iterations_without_imu,
//   solver_iterations_without_imu; registration_budget.h): the normal 2 rounds × 3 iterations stop
//   before converging and the error compounds (hdl32e quad walk 101, 2 s outage: 29 m, with the
//   larger budget 0.029 m);
// - keeps the prediction along its degenerate directions (LioOdometry::AnalyseDegeneracy);
// - if its estimate is implausible, goes back to the prediction: its lidar residuals leave the
//   window and its states get their starting values again, so that the next scan starts from the
//   prediction instead of from the diverged pose, which no later scan recovers from (lidar_only,
//   vlp16 park walk 100: 95 failed scans of 100 after a jump at its third scan);
// - in an IMU outage of an IMU method, is rejected the same way when the lidar moved it further
//   from the prediction than LidarFrontendOptions::max_correction_without_imu, or turned it further
//   than max_rotation_correction_without_imu (RejectsCorrection).
// Scans with IMU samples are untouched: runs without an outage are the same bit for bit.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

class ScanWithoutImu {
 public:
  // Whether `result`'s scan is one. Not the IMU-as-input baseline: it bridges a gap its own way
  // (constant-twist prediction, velocity random walk; nav_state_estimator.h), and with the budget
  // and the remapping it diverged on the 1 s outage of
  // lio.ImuDropout.EveryMethodRunsThroughAOneSecondOutage (a 5.1 m jump).
  static bool Applies(LioMethod method, const ScanResult& result);

  // The start of a scan: if `applies`, keeps the values of its states `keys` (the prediction).
  void Begin(bool applies, const std::vector<StateId>& keys, const SlidingWindow& window);
  // Whether the scan begun last is one.
  bool active() const { return !start_.empty(); }

  // Whether the scan begun last, of a method that `uses_imu`, is rejected for a correction from
  // its prediction (result->correction_m, correction_rad) above `options`' limits
  // (max_correction_without_imu, max_rotation_correction_without_imu; 0 = off): then `result` is
  // marked degenerate with the reason, and the caller restores it (Restore) and leaves its points
  // out of the map.
  // Never for lidar_only (uses_imu false): every one of its scans is one, and its prediction never
  // had the IMU's motion behind it (not measured for it: docs/experiments/imu-dropout.md).
  bool RejectsCorrection(bool uses_imu, const LidarFrontendOptions& options,
                         ScanResult* result) const;

  // After an implausible estimate: when active(), removes the scan's lidar residuals and restores
  // the starting values; returns whether it did.
  bool Restore(const RegistrationSummary& registered, SlidingWindow* window) const;

 private:
  std::vector<std::pair<StateId, Eigen::VectorXd>> start_;
};

}  // namespace ctlio::lio
