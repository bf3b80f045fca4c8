#include "ctlio/solvers/lio/sweep_keypoint_budget.h"

#include <cmath>
#include <stdexcept>

namespace ctlio::lio {

void SlowSweepKeypoints::Validate() const {
  if (!(max_keypoints >= 0 && max_keypoints <= 1000000)) {
    throw std::invalid_argument(
        "window.slow_sweep_max_keypoints must be in [0, 1000000] (0: "
        "lidar_frontend.max_keypoints)");
  }
  if (!(std::isfinite(speed) && speed > 0.0 && speed <= 1000.0)) {
    throw std::invalid_argument("window.slow_sweep_speed must be in (0, 1000] m/s");
  }
  if (!(std::isfinite(accel) && accel >= 0.0 && accel <= 1000.0)) {
    throw std::invalid_argument(
        "window.slow_sweep_accel must be in [0, 1000] m/s^2 (0: no acceleration condition)");
  }
}

int SweepKeypointCap(const AdaptiveKnotOptions& adaptive, const SlowSweepKeypoints& slow,
                     bool split, double speed, double accel) {
  if (split) return adaptive.max_keypoints;
  // A NaN speed or acceleration (a diverged estimate) is not slow: the front end's budget.
  if (!slow.enabled() || !std::isfinite(speed) || !(speed < slow.speed)) return 0;
  if (slow.accel > 0.0 && !(std::isfinite(accel) && accel < slow.accel)) return 0;
  return slow.max_keypoints;
}

}  // namespace ctlio::lio
