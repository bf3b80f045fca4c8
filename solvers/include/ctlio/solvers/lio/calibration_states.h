// The online calibration's states in the window (calibration_options.h: a clock offset per IMU and
// the extrinsic T_imu_lidar, static states the estimator adds): which blocks they are, their hold
// and release around a scan's solve, the observability assessment (calibration_observability.h)
// and the marginal covariance, both reported in ScanResult::calibration. LioOdometry owns one and
// calls it at three points of a scan (lio_odometry.h, Process):
//
//   Hold (before the registration) → registration → Release → … → Report (the scan estimated)
//
// The warm-up replay (calibrating_odometry.h) reaches it only through HoldUntil, set on the
// pipeline of its held pass.
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "ctlio/solvers/lio/calibration_observability.h"
#include "ctlio/solvers/lio/calibration_options.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

class CalibrationStates {
 public:
  CalibrationStates(const CalibrationOptions& options, int num_imus);

  // Holds the coordinates where `mask` is true (calibration order, as ScanResult::calibration's
  // vectors; empty: all of them) during the solve of every scan that ends at most `t_s` seconds
  // after the first scan began, at the value each such solve starts from.
  void HoldUntil(double t_s, std::vector<bool> mask);

  // The calibration states `window` holds (the baseline has none), in the order of the
  // coordinates: the clock offsets (1-D each), then the extrinsic.
  std::vector<StateId> Ids(const SlidingWindow& window) const;

  // Before the registration of the scan ending at `t_end` (seconds since the first scan began): a
  // strong prior at the current value along each coordinate of HoldUntil's mask while t_end is
  // within its span, otherwise (calibration.hold_unobservable) along each the previous scan left
  // unobservable, so that the solve does not move it; which ones into result->calibration.held.
  // Nothing without calibration states.
  void Hold(double t_end, SlidingWindow* window, ScanResult* result);
  // After the solve: removes Hold's priors before anything else reads the window.
  void Release(SlidingWindow* window);

  // After an estimated scan: with calibration.observability_horizon_scans > 0, the information of
  // the factors on `newest_keys` (the newest state's blocks) on the calibration coordinates into
  // the horizon, ν and the unobservable coordinates into result->calibration; and their marginal
  // σ (the inverse of their marginal information in the whole window, the window's
  // pseudo-inverse; NaN when that is not positive definite).
  void Report(const std::vector<StateId>& newest_keys, SlidingWindow* window, ScanResult* result);

  // The assessment so far (nullptr before the first one, or without the check).
  const CalibrationObservability* observability() const { return observability_.get(); }

 private:
  void Assess(const std::vector<StateId>& newest_keys, const SlidingWindow& window,
              ScanResult* result);
  void ReportCovariance(SlidingWindow* window, ScanResult* result) const;
  // Creates observability_ over the states in `window`; false when there are none or the check
  // is off.
  bool StartObservability(const SlidingWindow& window);

  CalibrationOptions options_;
  int num_imus_ = 0;
  std::unique_ptr<CalibrationObservability> observability_;
  std::vector<ceres::ResidualBlockId> holds_;  // this scan's hold priors
  double hold_until_s_ = -1.0;                 // HoldUntil
  std::vector<bool> hold_mask_;
};

}  // namespace ctlio::lio
