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
}

int SweepKeypointCap(const AdaptiveKnotOptions& adaptive, const SlowSweepKeypoints& slow,
                     bool split, double speed) {
  if (split) return adaptive.max_keypoints;
  // A NaN speed (a diverged estimate) is not slow: the front end's budget.
  if (slow.enabled() && std::isfinite(speed) && speed < slow.speed) return slow.max_keypoints;
  return 0;
}

}  // namespace ctlio::lio
