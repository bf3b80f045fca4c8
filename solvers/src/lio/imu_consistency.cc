#include "ctlio/solvers/lio/imu_consistency.h"

#include <ceres/cost_function.h>

#include <cmath>
#include <limits>

#include "ctlio/factors/imu/imu_interval_batch.h"

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
  // Interval blocks (imu_interval_batch.h) hold both sensors' rows, scaled by the loss: each
  // gives its own unrobustified χ² per sensor. The per-sample blocks are evaluated together.
  ImuTermBlocks single;
  ChiSquare batch_accel, batch_gyro;
  bool batch_ok = true;
  std::vector<double*> parameters;
  for (const std::vector<ceres::ResidualBlockId>* list : {&blocks.accel, &blocks.gyro}) {
    for (const ceres::ResidualBlockId id : *list) {
      const auto* batch =
          dynamic_cast<const imu::ImuIntervalBatch*>(problem->GetCostFunctionForResidualBlock(id));
      if (batch == nullptr) {
        (list == &blocks.accel ? single.accel : single.gyro).push_back(id);
        continue;
      }
      problem->GetParameterBlocksForResidualBlock(id, &parameters);
      double a = 0.0, g = 0.0;
      batch_ok = batch->ChiSquare(parameters.data(), &a, &g) && batch_ok;
      const int dof = 3 * static_cast<int>(batch->size());
      batch_gyro.chi2 += g;
      batch_gyro.dof += dof;
      if (!batch->accelerometer()) continue;
      batch_accel.chi2 += a;
      batch_accel.dof += dof;
    }
  }
  *accel = {0.0, Residuals(*problem, single.accel)};
  *gyro = {0.0, Residuals(*problem, single.gyro)};
  if (accel->dof + gyro->dof > 0) {
    ceres::Problem::EvaluateOptions options;
    options.residual_blocks = single.accel;
    options.residual_blocks.insert(options.residual_blocks.end(), single.gyro.begin(),
                                   single.gyro.end());
    options.apply_loss_function = false;
    std::vector<double> r;
    if (!problem->Evaluate(options, nullptr, &r, nullptr, nullptr) ||
        static_cast<int>(r.size()) != accel->dof + gyro->dof) {
      batch_ok = false;
    } else {
      // The accelerometer blocks come first (their order in residual_blocks).
      for (int i = 0; i < accel->dof; ++i) accel->chi2 += r[i] * r[i];
      for (size_t i = accel->dof; i < r.size(); ++i) gyro->chi2 += r[i] * r[i];
    }
  }
  accel->chi2 += batch_accel.chi2;
  accel->dof += batch_accel.dof;
  gyro->chi2 += batch_gyro.chi2;
  gyro->dof += batch_gyro.dof;
  if (!batch_ok) accel->chi2 = gyro->chi2 = std::numeric_limits<double>::quiet_NaN();
}

}  // namespace ctlio::lio
