// IMU as a measurement of the state (the paper's method, SPEC §3): one gyro or
// accelerometer sample at its own time τ ∈ [t_k, t_{k+1}], compared with the GP
// state interpolated between two SE(3) knots (gp::GpInterpolator::State; the
// interpolation is never re-derived here) and with the bias interpolated
// linearly, b(τ) = (1 − s)b_k + s·b_{k+1}, s = (τ − t_k)/(t_{k+1} − t_k).
//
// Conventions (SPEC §1): T = T_rm (robot ← map), ϖ = −[v; ω] the negated body
// twist in the robot frame ([ρ; φ] order: ϖ_v = ϖ.head<3>, ϖ_ω = ϖ.tail<3>),
// b = [b_a; b_g]. Gravity g_i = [0, 0, −|g|] in a gravity-aligned frame i; C_mi
// rotates i into the map frame. By default the IMU frame is the robot frame; an
// ImuMounting (imu_mounting.h: C_ri, lever arm p) places it elsewhere, and the
// measurement, its noise and its bias are then in the IMU's own frame.
//
// Gyro:  e_g = ω_m + ϖ_ω(τ) − b_g(τ)                        (ω = −ϖ_ω)
// Accelerometer. The IMU reads f = C_rm(p̈ − g_m) = v̇_b + ω×v_b − C_rm g_m with
// v_b = −ϖ_v, ω = −ϖ_ω (Ċ_rm = −ω^C_rm), i.e. f = −ϖ̇_v + ϖ_ω×ϖ_v − C_rm C_mi g_i:
//   kSpecificForce (exact; the default):
//                 e_a = f_m + ϖ̇_v(τ) − ϖ_ω(τ)×ϖ_v(τ) + C_rm(τ) C_mi g_i − b_a(τ)
//   kBodyCentric  (the paper's approximation, no ω×v term; pass it explicitly to reproduce
//                 the paper):
//                 e_a = f_m + ϖ̇_v(τ) + C_rm(τ) C_mi g_i − b_a(τ)
// With a mounting (rigid-body kinematics, imu_mounting.h; ω = −ϖ_ω, ω̇ = −ϖ̇_ω):
//   e_g = ω_m + C_ir ϖ_ω(τ) − b_g(τ)
//   e_a = f_m + C_ir [ϖ̇_v + C_rm C_mi g_i (− ϖ_ω×ϖ_v) − p×ϖ̇_ω − ϖ_ω×(ϖ_ω×p)] − b_a
// (the last two terms are −ω̇×p − ω×(ω×p), in both accelerometer models: they are the
// rigid-body motion of the IMU's origin, not the ω×v the paper's model leaves out).
// Both residuals are whitened by S with SᵀS = Σ⁻¹ (Σ the 3×3 sample covariance);
// the robust loss (the paper: Cauchy, scale 1, on the whitened accelerometer
// error) is the caller's choice in AddResidualBlock.
//
// Jacobians: with D = ∂e/∂[δT; δϖ; δϖ̇](τ) (3×18) the knot Jacobians are D·J_k
// and D·J_{k+1} from the interpolator, split into the pose (6, lifted with
// LiftPoseJacobian), ϖ (6) and ϖ̇ (6) columns. For T ← Exp(δ)T, C ← Exp(δφ)C:
//   gyro:  ∂e_g/∂ϖ_ω = I;
//   accel: ∂e_a/∂δφ = −(C C_mi g_i)^, ∂e_a/∂ϖ̇_v = I, and for kSpecificForce
//          ∂e_a/∂ϖ_v = −ϖ_ω^, ∂e_a/∂ϖ_ω = ϖ_v^;
//   mounting: every row above is premultiplied by C_ir, and the lever arm adds
//          ∂e_a/∂ϖ̇_ω = −C_ir p^, ∂e_a/∂ϖ_ω += C_ir [(ϖ_ω×p)^ + ϖ_ω^ p^];
//   gravity rotation C_mi ← Exp(ψ)C_mi: ∂e_a/∂ψ = −C (C_mi g_i)^ (lifted with
//          LiftRotationJacobian, premultiplied by C_ir; hold the block constant with
//          Problem::SetParameterBlockConstant when C_mi is not estimated);
//   biases: ∂e/∂b_k = −(1 − s)·P, ∂e/∂b_{k+1} = −s·P, P selecting b_a or b_g.
//
// Interpolation: each factor reads x(τ) from a gp::SharedStateInterpolation. The gyro and the
// accelerometer residual of one sample share one (the second constructor; a window's evaluation
// callback prepares it once per evaluation point, solvers/shared_interpolation_callback.h), so the
// sample's interpolation is formed once; the first constructor gives a factor its own. The two
// stay separate residual blocks because the robust loss (Cauchy) is on the accelerometer only.
//
// Parameter blocks:
//   ImuGyroMeasurement:  pose_k, ϖ_k, ϖ̇_k, pose_k+1, ϖ_k+1, ϖ̇_k+1, b_k, b_k+1
//                        (7, 6, 6, 7, 6, 6, 6, 6)
//   ImuAccelMeasurement: the same, then C_mi (4, RotationManifold).
#pragma once

#include <ceres/sized_cost_function.h>

#include <memory>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/factors/imu/imu_residual.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

class ImuGyroMeasurement final : public ceres::SizedCostFunction<3, 7, 6, 6, 7, 6, 6, 6, 6> {
 public:
  // gyro: ω_m (rad/s) at time tau; covariance: of one sample (rad²/s²).
  ImuGyroMeasurement(const gp::SingerModel<6>& model, double t_k, double t_k1, double tau,
                     const Vec3& gyro, const Mat3& covariance,
                     const ImuMounting& mounting = ImuMounting());
  // At the time of `state`, which this factor may share with the sample's accelerometer factor
  // (adds the rows it reads to `state`).
  ImuGyroMeasurement(std::shared_ptr<gp::SharedStateInterpolation> state, const Vec3& gyro,
                     const Mat3& covariance, const ImuMounting& mounting = ImuMounting());

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The state rows the residual reads (gp::StateRowBlock flags).
  static unsigned Rows() { return gp::kAngularVelocityRows; }

 private:
  std::shared_ptr<const gp::SharedStateInterpolation> state_;
  double s_;  // (τ − t_k)/(t_{k+1} − t_k)
  internal::GyroResidual residual_;
};

class ImuAccelMeasurement final : public ceres::SizedCostFunction<3, 7, 6, 6, 7, 6, 6, 6, 6, 4> {
 public:
  // accel: f_m (m/s²) at time tau; covariance of one sample; gravity: |g|.
  ImuAccelMeasurement(const gp::SingerModel<6>& model, double t_k, double t_k1, double tau,
                      const Vec3& accel, const Mat3& covariance, double gravity = 9.81,
                      AccelModel accel_model = AccelModel::kSpecificForce,
                      const ImuMounting& mounting = ImuMounting());
  // At the time of `state`, which this factor may share with the sample's gyro factor (adds the
  // rows it reads to `state`).
  ImuAccelMeasurement(std::shared_ptr<gp::SharedStateInterpolation> state, const Vec3& accel,
                      const Mat3& covariance, double gravity = 9.81,
                      AccelModel accel_model = AccelModel::kSpecificForce,
                      const ImuMounting& mounting = ImuMounting());

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The state rows the residual reads (gp::StateRowBlock flags): δφ and ϖ̇_v, ϖ for the exact
  // model, ϖ_ω and ϖ̇_ω for a lever arm.
  static unsigned Rows(AccelModel accel_model, const ImuMounting& mounting) {
    return internal::AccelResidual::Rows(accel_model, mounting);
  }

 private:
  std::shared_ptr<const gp::SharedStateInterpolation> state_;
  double s_;
  internal::AccelResidual residual_;
};

}  // namespace ctlio::imu
