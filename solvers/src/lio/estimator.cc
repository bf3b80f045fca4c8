#include "ctlio/solvers/lio/estimator.h"

#include "ctlio/solvers/lio/gp_knot_estimator.h"
#include "ctlio/solvers/lio/nav_state_estimator.h"

namespace ctlio::lio {

std::unique_ptr<Estimator> MakeEstimator(const OdometryConfig& config, const ImuBuffer& imu) {
  if (config.method == LioMethod::kImuInput) {
    return std::make_unique<NavStateEstimator>(config, imu);
  }
  return std::make_unique<GpKnotEstimator>(config, imu);
}

}  // namespace ctlio::lio
