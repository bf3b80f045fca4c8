// The initial guess of a new GP knot from the IMU samples since the previous one: the previous
// knot's state carried forward sample by sample, each gyro sample giving ϖ_ω and each
// accelerometer sample the ϖ̇_v at which its own measurement residual vanishes
// (AccelResidual::ZeroingLinearAcceleration, the model of imu_measurement.h; no second copy).
//
// Why: LM starts from this guess, and the accelerometer residuals carry a Cauchy loss
// (imu.accel_loss_scale). With the constant-velocity guess (ϖ̇ = 0) an acceleration step, like the
// simulator's motion start (SPEC §6: ~7 m/s² in medium, ~28 in fast, from rest), puts every
// sample of the sweep tens of σ out, where the loss has all but switched them off; the solve then
// stays near the guess and the lidar alone pulls the pose.
#pragma once

#include <vector>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/factors/imu/imu_residual.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

struct TimedImuSample {
  double t = 0.0;  // when the sample measures the state (odometry seconds, offset applied)
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
};

struct ImuPredictionModel {
  imu::ImuMounting mounting;
  double gravity = 9.81;
  imu::AccelModel accel_model = imu::AccelModel::kSpecificForce;
  bool has_accelerometer = true;  // false (lidar_gyro): ϖ_v stays the previous knot's
};

// The state at t > t_prev from the previous knot's (T_rm, ϖ, ϖ̇) at t_prev, the samples in
// (t_prev, t] in time order (times outside are clamped into it), the IMU's bias [b_a; b_g] and
// C_mi. Between samples ϖ̇_v is linear and ϖ_v integrates it (trapezoid), ϖ_ω is linear, and
// ϖ̇_ω at a sample is the slope of the quadratic through it and its neighbours; after the last
// sample ϖ_ω and ϖ̇ are held. Without samples: constant ϖ and ϖ̇ = 0 (the guess without an IMU).
gp::KnotState PredictKnotWithImu(const gp::KnotState& prev, double t_prev, double t,
                                 const std::vector<TimedImuSample>& samples, const Vec6& bias,
                                 const Mat3& C_mi, const ImuPredictionModel& model);

}  // namespace ctlio::lio
