#include "ctlio/solvers/lio/bias_priors.h"

#include <algorithm>

#include "ctlio/factors/imu/bias_factors.h"
#include "ctlio/factors/priors/euclidean_prior.h"

namespace ctlio::lio {

ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt) {
  // BiasRandomWalk wants the density (variance per second) and scales it by Δt.
  return new imu::BiasRandomWalk(config.bias_accel_walk / config.bias_walk_period,
                                 config.bias_gyro_walk / config.bias_walk_period,
                                 std::max(dt, 1e-6));
}

ceres::CostFunction* MakeInitialBiasPrior(const OdometryConfig& config) {
  Vec6 variance;
  variance << Vec3::Constant(config.initial_bias_accel_variance),
      Vec3::Constant(config.initial_bias_gyro_variance);
  return EuclideanPrior<6>::FromCovariance(Vec6::Zero(), variance.asDiagonal().toDenseMatrix());
}

}  // namespace ctlio::lio
