// The accelerometer's robust loss through the start-up (Singer-LIO;
// imu.accel_loss_relax_bias_sigma, imu.accel_loss_relaxed_scale).
//
// Singer-LIO puts a Cauchy loss on the whitened accelerometer error (imu.accel_loss_scale). At the
// start the accelerometer bias is free under its initial prior (σ 0.32 m/s² per axis with the
// shipped 0.1 (m/s²)², against a device σ of 0.008–0.05 m/s² per sample), and at full weight the
// accelerometer residuals trade that bias against the velocity and the lidar's weakest direction:
// without the loss every VLP-16 park walk of the tuning indices diverged, while a bias held near
// its true value did not (docs/experiments/scoreboard.md, "Walking and vehicle: budget or
// estimator?"). Kept on all run long, the loss also down-weights the accelerometer once its bias is
// known, and the park cells lean on the accelerometer (without it 3–4.5× the ATE).
//
// The schedule keeps the configured scale until the window's marginal covariance of IMU j's
// accelerometer bias (Gauss–Newton, SlidingWindow::Covariance) has its largest standard deviation
// below the threshold, and from then on gives every new interval of that IMU the relaxed scale
// (0: no loss). Latched: the bias walk lets the marginal σ breathe a little from scan to scan, and
// a loss that switched back and forth with it would change the problem's weights between scans for
// no physical reason; a reset builds a new estimator, and with it a new schedule.
#pragma once

#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

class AccelLossSchedule {
 public:
  // relax_bias_sigma 0: the configured scale all run long (the schedule never asks for a
  // covariance).
  AccelLossSchedule(double scale, double relax_bias_sigma, double relaxed_scale, int num_imus);

  bool enabled() const { return relax_bias_sigma_ > 0.0; }
  // IMU `imu`'s accelerometer-bias covariance is still wanted: enabled and not yet relaxed.
  bool Watching(int imu) const;
  // The marginal covariance of IMU `imu`'s accelerometer bias (3×3, m²/s⁴): relaxes the loss of
  // that IMU once its largest σ is below the threshold. A covariance that is not finite or has no
  // positive eigenvalue (a pseudo-inverse's unobserved direction reads 0, not "known") is no
  // evidence and relaxes nothing.
  void Observe(int imu, const Mat3& accel_bias_covariance);
  bool relaxed(int imu) const { return relaxed_[imu]; }
  // The Cauchy scale for IMU `imu`'s next interval (0: no loss).
  double scale(int imu) const { return relaxed_[imu] ? relaxed_scale_ : scale_; }
  // The largest σ the last Observe of IMU `imu` read [m/s²] (0 before any).
  double last_sigma(int imu) const { return last_sigma_[imu]; }

  // √(largest eigenvalue) of a symmetric 3×3 covariance; NaN if not finite or not positive.
  static double LargestSigma(const Mat3& covariance);

 private:
  double scale_;
  double relax_bias_sigma_;
  double relaxed_scale_;
  std::vector<bool> relaxed_;
  std::vector<double> last_sigma_;
};

}  // namespace ctlio::lio
