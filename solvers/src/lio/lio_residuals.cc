#include "ctlio/solvers/lio/lio_residuals.h"

#include <algorithm>
#include <cmath>

#include "ctlio/factors/imu/bias_factors.h"

namespace ctlio::lio {

std::unique_ptr<ceres::LossFunction> MakeLidarLoss(const OdometryConfig& config) {
  const double scale = config.frontend.loss_scale / config.frontend.point_noise_sigma;
  if (config.frontend.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(scale);
  if (config.frontend.loss == "huber") return std::make_unique<ceres::HuberLoss>(scale);
  return nullptr;
}

ceres::Solver::Options WindowSolverOptions(const OdometryConfig& config) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  o.max_num_iterations = config.frontend.solver_iterations;
  o.num_threads = config.solver_threads;
  o.minimizer_progress_to_stdout = false;
  o.logging_type = ceres::SILENT;
  return o;
}

ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt) {
  // The config gives the variance accumulated per bias_walk_period; BiasRandomWalk wants the
  // density (variance per second) and scales it by Δt.
  return new imu::BiasRandomWalk(config.bias_accel_walk / config.bias_walk_period,
                                 config.bias_gyro_walk / config.bias_walk_period,
                                 std::max(dt, 1e-6));
}

}  // namespace ctlio::lio
