// The accelerometer measurement (imu_measurement.h, same residual: imu_residual.h) of a sample
// stamped t on an IMU clock offset by an estimated δ from the state's (lidar) clock: the sample
// measures the GP state at τ = t + δ.
//
//   e_a(δ) = e_a(x(τ), C_mi, b_a(τ)),  τ = t + δ,
//   ∂e_a/∂δ = D·ẋ(τ) − S·(b_{a,k+1} − b_{a,k})/(t_{k+1} − t_k),
// with D = ∂e_a/∂[δT; δϖ; δϖ̇] (imu_measurement.h) and ẋ(τ) the time derivative of the
// interpolated state (gp::GpInterpolator). Interval and clamping as in imu_gyro_time_offset.h.
//
// Parameter blocks: pose_k, ϖ_k, ϖ̇_k, pose_k+1, ϖ_k+1, ϖ̇_k+1, b_k, b_k+1, C_mi, δ
//                   (7, 6, 6, 7, 6, 6, 6, 6, 4, 1).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/factors/imu/imu_residual.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

class ImuAccelMeasurementWithTimeOffset final
    : public ceres::SizedCostFunction<3, 7, 6, 6, 7, 6, 6, 6, 6, 4, 1> {
 public:
  // accel: f_m (m/s²) stamped `stamp` on the IMU's clock; covariance of one sample; |g|.
  ImuAccelMeasurementWithTimeOffset(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                    double stamp, const Vec3& accel, const Mat3& covariance,
                                    double gravity = 9.81,
                                    AccelModel accel_model = AccelModel::kSpecificForce,
                                    const ImuMounting& mounting = ImuMounting());

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  gp::SingerModel<6> model_;
  double t_k_, t_k1_, stamp_;
  internal::AccelResidual residual_;
};

}  // namespace ctlio::imu
