// Knot spacing chosen from the motion of each sweep (window.adaptive_knots_*, the GP methods).
// One knot per sweep interpolates the sweep's motion with one SE(3) Singer interval: its mean
// carries ϖ and ϖ̇ at both ends, so an angular rate that changes linearly over the sweep (constant
// angular acceleration) is followed, and what it cannot follow is the rate's curvature (angular
// jerk: handheld shaking at 4–8 Hz). That part is measured here from the sweep's own gyro samples:
// the RMS over the samples of the norm of their residual about the least-squares straight line in
// time of each axis (the bias drops out of the line fit, and a rotation of the mounting does not
// change the norm). For a rate ω(t) with curvature c = ω̈/2 the residual of a line over an
// interval of length T is |c|·T²/√180, so K equal intervals shrink it by K²: the sweep gets the
// fewest knots K (from knots_per_scan up to adaptive_knots_max) with r / K² ≤ threshold, r the
// measured residual.
// A sweep whose residual stays below the threshold keeps knots_per_scan: the estimator's problem
// is the one of a fixed knot count, bit for bit.
#pragma once

#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

struct AdaptiveKnotOptions {
  // Most knots a sweep may get; ≤ knots_per_scan turns the rule off (the default in code).
  int max_knots_per_scan = 1;
  // Threshold on the gyro residual about its line over the sweep [rad/s]; 0: not used.
  double gyro_curvature = 0.0;
  // Threshold on the accelerometer residual about its line over the sweep [m/s²]; 0: not used.
  double accel_curvature = 0.0;
  // On a sweep the rule gives more knots than knots_per_scan, the IMU measurement variances are
  // at least these (accelerometer [(m/s²)²], gyro [(rad/s)²]; 0: the configured ones): there the
  // whitened IMU error is dominated by what the GP mean between knots cannot follow of a motion
  // curved at 4–8 Hz, not by the device noise a sensor file's variances were set from
  // (docs/experiments/knot-spacing.md).
  double accel_variance_floor = 0.0;
  double gyro_variance_floor = 0.0;
  // On such a sweep, at most this many keypoints instead of lidar_frontend.max_keypoints (0: the
  // same cap), chosen from the sweep's preprocessed points as the front end chooses them
  // (KeypointsOf). The lidar, not the GP's interpolation, limits a split sweep's estimate: with
  // two knots the fitted IMU residuals are at the device noise (docs/experiments/knot-spacing.md).
  int max_keypoints = 0;

  bool enabled(int knots_per_scan) const {
    return max_knots_per_scan > knots_per_scan && (gyro_curvature > 0.0 || accel_curvature > 0.0);
  }
};

// The RMS over the samples of |x_i − (a + b·t_i)|, the per-axis least-squares line through
// (t_i, x_i); 0 with fewer than three samples or no spread in time.
double LineResidualRms(const std::vector<double>& t, const std::vector<Vec3>& x);

// The sweep's knot count: knots_per_scan unless the options are enabled and a measured residual
// (gyro or accelerometer, each against its own threshold) asks for more, then the fewest K with
// residual / K² ≤ threshold, at most max_knots_per_scan.
int KnotsForSweep(const AdaptiveKnotOptions& options, int knots_per_scan,
                  const std::vector<double>& t, const std::vector<Vec3>& gyro,
                  const std::vector<Vec3>& accel);

}  // namespace ctlio::lio
