// The whitened χ² of a scan's IMU terms at its final estimate: the per-scan half of the run's
// IMU–lidar consistency check (apps/lio/run_checks.h, docs/user-guide/bad-input.md).
//
// Every IMU residual is whitened by its cost function, r = Σ^{-1/2}·e, so with the configured
// noise right and the estimate near the truth E‖r‖² = dim r: χ²/dof ≈ 1. An accelerometer the
// estimate cannot agree with — its sign flipped (f' = −f reads like an upside-down IMU at rest,
// so the gravity check passes, but gives −2·C_bm·a_m against the lidar's motion while the
// platform accelerates), axes swapped, the wrong units — or a noise setting far too small leaves
// χ²/dof ≫ 1 where the lidar wins over the accelerometer. Where the estimate follows the
// accelerometer instead (the attitude tilts so that gravity explains it), the IMU terms stay
// satisfied and the lidar's cost grows: not seen here (measured: bad-input.md). The robust loss
// is not applied: the Cauchy loss of the accelerometer would cap the residuals that tell.
#pragma once

#include <ceres/problem.h>

#include <vector>

namespace ctlio::lio {

// The IMU residual blocks one scan added to the window, by sensor. Singer-LIO: one accelerometer
// and one gyro block per sample (3 components each), or with imu.residual_blocks: interval one
// imu::ImuIntervalBatch per interval and IMU in `accel` (it reports each sensor's χ² itself);
// lidar_gyro: gyro blocks only (or its interval blocks, in `gyro`); the IMU-as-input baseline: its
// preintegrated IMU factor ([φ; v; p], 9 components, driven by both sensors and not separable once
// whitened) in `accel`, no gyro block.
struct ImuTermBlocks {
  std::vector<ceres::ResidualBlockId> accel;
  std::vector<ceres::ResidualBlockId> gyro;
  void clear() {
    accel.clear();
    gyro.clear();
  }
};

struct ChiSquare {
  double chi2 = 0.0;  // Σ‖r_i‖² of the whitened residuals, no loss function
  int dof = 0;        // Σ dim r_i
};

// χ² of `accel` and `gyro` at the parameters' current values in one ceres::Problem::Evaluate
// (EvaluateOptions::residual_blocks, apply_loss_function = false; Ceres runs the problem's
// EvaluationCallback first, so shared interpolations are current). Empty lists give {0, 0}. A
// failed evaluation or a non-finite residual gives χ² = NaN with the counts kept.
void EvaluateImuChiSquare(ceres::Problem* problem, const ImuTermBlocks& blocks, ChiSquare* accel,
                          ChiSquare* gyro);

}  // namespace ctlio::lio
