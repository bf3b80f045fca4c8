// The keypoint budget of a sweep that follows the motion (the GP methods): a split sweep
// (knot_spacing.h) has window.adaptive_knots_max_keypoints; an unsplit sweep whose estimated
// speed is below window.slow_sweep_speed has window.slow_sweep_max_keypoints; every other sweep
// keeps lidar_frontend.max_keypoints. The speed is the estimator's own: the norm of the linear
// part of the newest solved knot's twist ϖ at the sweep's start, never the ground truth.
// Why: on the 64/128-beam Ouster models Singer-LIO's walks gain from ~1200 keypoints (quad walk,
// tuning indices 100–102: OS1-64 1.08 → 0.82 cm against the baseline's 0.93 at 0.87× its CPU)
// while its town drive loses with them (3.12 → 3.35 against 3.23; docs/experiments/scoreboard.md).
// Walks are at 1.2–1.6 m/s and drives at 8–14 m/s, so one threshold between them separates the
// two without hysteresis: each sweep's keypoints are chosen on their own, and a sweep near the
// threshold costs only its own budget.
#pragma once

#include "ctlio/solvers/lio/knot_spacing.h"

namespace ctlio::lio {

struct SlowSweepKeypoints {
  // window.slow_sweep_max_keypoints: at most this many keypoints on an unsplit sweep slower than
  // `speed` (0: off, the default in code: lidar_frontend.max_keypoints, bit for bit).
  int max_keypoints = 0;
  // window.slow_sweep_speed [m/s]: the threshold on the estimated speed (strictly below: slow).
  double speed = 4.0;

  bool enabled() const { return max_keypoints > 0; }
  // Throws std::invalid_argument naming the key: budget in [0, 1000000], speed in (0, 1000].
  void Validate() const;
};

// The sweep's keypoint cap: 0 means the front end's keypoints (lidar_frontend.max_keypoints). A
// split sweep: adaptive.max_keypoints; an unsplit one: slow.max_keypoints when enabled and
// `speed` (the estimated speed [m/s]) is finite and below slow.speed; else 0.
int SweepKeypointCap(const AdaptiveKnotOptions& adaptive, const SlowSweepKeypoints& slow,
                     bool split, double speed);

}  // namespace ctlio::lio
