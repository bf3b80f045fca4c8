// The gyro measurement (imu_measurement.h, same residual: imu_residual.h) of a sample stamped t on
// an IMU clock offset by an estimated δ from the state's (lidar) clock: the sample measures the
// GP state at τ = t + δ (δ > 0: the IMU's stamps are late).
//
//   e_g(δ) = S(ω_m + C_ir ϖ_ω(τ) − b_g(τ)),  τ = t + δ,  b(τ) = (1 − s)b_k + s·b_{k+1},
//   s = (τ − t_k)/(t_{k+1} − t_k),
//   ∂e_g/∂δ = D·ẋ(τ) − S·(b_{g,k+1} − b_{g,k})/(t_{k+1} − t_k),
// with ẋ(τ) the time derivative of the interpolated state (gp::GpInterpolator, Λ'(τ), Ω'(τ)).
// The interpolation coefficients are formed at τ on every evaluation (τ moves with δ), so this
// factor does not share its interpolation with the accelerometer's.
//
// Interval: the caller assigns the sample to [t_k, t_{k+1}] with its current estimate of δ; if
// the optimiser moves τ outside, τ is clamped to the interval's end (the residual is then that of
// the end and ∂e/∂δ = 0 there: the GP interpolation between two knots is not defined outside
// them). With the window re-solved every scan this touches only samples within |Δδ| of a knot.
//
// Parameter blocks: pose_k, ϖ_k, ϖ̇_k, pose_k+1, ϖ_k+1, ϖ̇_k+1, b_k, b_k+1, δ
//                   (7, 6, 6, 7, 6, 6, 6, 6, 1).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/factors/imu/imu_residual.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

class ImuGyroMeasurementWithTimeOffset final
    : public ceres::SizedCostFunction<3, 7, 6, 6, 7, 6, 6, 6, 6, 1> {
 public:
  // gyro: ω_m (rad/s) stamped `stamp` on the IMU's clock; covariance: of one sample.
  ImuGyroMeasurementWithTimeOffset(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                   double stamp, const Vec3& gyro, const Mat3& covariance,
                                   const ImuMounting& mounting = ImuMounting());

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  gp::SingerModel<6> model_;
  double t_k_, t_k1_, stamp_;
  internal::GyroResidual residual_;
};

}  // namespace ctlio::imu
