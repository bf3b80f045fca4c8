#include "ctlio/solvers/lio/imu_consistency.h"

#include <ceres/cost_function.h>

#include <cmath>
#include <limits>

namespace ctlio::lio {

namespace {

int Residuals(const ceres::Problem& problem, const std::vector<ceres::ResidualBlockId>& blocks) {
  int n = 0;
  for (const ceres::ResidualBlockId id : blocks) {
    n += problem.GetCostFunctionForResidualBlock(id)->num_residuals();
  }
  return n;
}

}  // namespace

void EvaluateImuChiSquare(ceres::Problem* problem, const ImuTermBlocks& blocks, ChiSquare* accel,
                          ChiSquare* gyro) {
  *accel = {0.0, Residuals(*problem, blocks.accel)};
  *gyro = {0.0, Residuals(*problem, blocks.gyro)};
  if (accel->dof + gyro->dof == 0) return;
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = blocks.accel;
  options.residual_blocks.insert(options.residual_blocks.end(), blocks.gyro.begin(),
                                 blocks.gyro.end());
  options.apply_loss_function = false;
  std::vector<double> r;
  if (!problem->Evaluate(options, nullptr, &r, nullptr, nullptr) ||
      static_cast<int>(r.size()) != accel->dof + gyro->dof) {
    accel->chi2 = gyro->chi2 = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  // The accelerometer blocks come first (their order in residual_blocks).
  for (int i = 0; i < accel->dof; ++i) accel->chi2 += r[i] * r[i];
  for (size_t i = accel->dof; i < r.size(); ++i) gyro->chi2 += r[i] * r[i];
}

}  // namespace ctlio::lio
