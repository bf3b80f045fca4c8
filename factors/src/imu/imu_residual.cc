#include "ctlio/factors/imu/imu_residual.h"

#include <Eigen/LU>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio::imu {

Mat3 SqrtInformation(const Mat3& covariance) {
  return SqrtInformationFromCovariance<3>(covariance, "IMU measurement covariance");
}

namespace internal {

GyroResidual::GyroResidual(const Vec3& gyro, const Mat3& covariance, const ImuMounting& mounting)
    : gyro_(gyro),
      sqrt_information_(SqrtInformation(covariance)),
      C_ir_(mounting.C_ri.transpose()),
      S_C_ir_(sqrt_information_ * C_ir_),
      rotated_(mounting.HasRotation()) {}

unsigned AccelResidual::Rows(AccelModel accel_model, const ImuMounting& mounting) {
  const bool exact = accel_model == AccelModel::kSpecificForce;
  return gp::kRotationRows | gp::kLinearAccelerationRows |
         (exact ? gp::kLinearVelocityRows | gp::kAngularVelocityRows : 0u) |
         (mounting.HasLeverArm() ? gp::kAngularVelocityRows | gp::kAngularAccelerationRows : 0u);
}

AccelResidual::AccelResidual(const Vec3& accel, const Mat3& covariance, double gravity,
                             AccelModel accel_model, const ImuMounting& mounting)
    : accel_(accel),
      sqrt_information_(SqrtInformation(covariance)),
      gravity_i_(0.0, 0.0, -gravity),
      accel_model_(accel_model),
      C_ir_(mounting.C_ri.transpose()),
      S_C_ir_(sqrt_information_ * C_ir_),
      rotated_(mounting.HasRotation()),
      lever_arm_(mounting.lever_arm),
      lever_arm_nonzero_(mounting.HasLeverArm()),
      rows_(Rows(accel_model, mounting)) {}

Vec3 AccelResidual::Evaluate(const gp::KnotState& x, const Mat3& C_mi, const Vec3& ba,
                             Linearisation* lin) const {
  const bool exact = accel_model_ == AccelModel::kSpecificForce;
  const bool lever = lever_arm_nonzero_;
  const Mat3& C = x.pose.rotation();  // C_rm(τ)
  const Vec3 g_m = C_mi * gravity_i_;
  const Vec3 g_r = C * g_m;
  const Vec3 w_v = x.velocity.head<3>(), w_w = x.velocity.tail<3>();
  // e = f_m + C_ir e_r − b_a, e_r the robot-frame terms (imu_measurement.h), summed in this order
  // so that the default mounting reproduces the robot-frame residual to the last bit.
  const auto to_imu = [this](const Vec3& v) { return rotated_ ? Vec3(C_ir_ * v) : v; };
  Vec3 e = accel_ + to_imu(x.acceleration.head<3>()) + to_imu(g_r) - ba;
  if (exact) e -= to_imu(w_w.cross(w_v));
  if (lever) {
    e -= to_imu(lever_arm_.cross(x.acceleration.tail<3>()) + w_w.cross(w_w.cross(lever_arm_)));
  }
  if (lin != nullptr) {
    // D = C_ir [−(g_r)^ on δφ, I on ϖ̇_v (− ϖ_ω^ on ϖ_v + ϖ_v^ on ϖ_ω)
    //           (− p^ on ϖ̇_ω + ((ϖ_ω×p)^ + ϖ_ω^ p^) on ϖ_ω)].
    lin->G = -so3::Hat(g_r);
    lin->W = exact ? Mat3(so3::Hat(w_v)) : Mat3::Zero();  // ∂e_r/∂ϖ_ω
    if (lever) lin->W += so3::Hat(w_w.cross(lever_arm_)) + so3::Hat(w_w) * so3::Hat(lever_arm_);
    lin->Hww = so3::Hat(w_w);
    lin->C = C;
    lin->g_m = g_m;
  }
  return sqrt_information_ * e;
}

Vec3 AccelResidual::ZeroingLinearAcceleration(const gp::KnotState& x, const Mat3& C_mi,
                                              const Vec3& ba) const {
  gp::KnotState x0 = x;
  x0.acceleration.head<3>().setZero();
  const Vec3 e0 = sqrt_information_.partialPivLu().solve(Evaluate(x0, C_mi, ba, nullptr));
  return rotated_ ? Vec3(-(C_ir_.transpose() * e0)) : Vec3(-e0);
}

void InterpolateShifted(const gp::SingerModel<6>& model, double t_k, double t_k1, double stamp,
                        double delta, unsigned rows, double const* const* parameters,
                        bool knot_jacobians, bool rate, TimeShiftedState* out) {
  const double tau_free = stamp + delta;
  const bool clamped = !(tau_free > t_k && tau_free < t_k1);
  const double tau = tau_free <= t_k ? t_k : tau_free >= t_k1 ? t_k1 : tau_free;
  const gp::GpInterpolator interpolator(model, t_k, t_k1, tau, rate && !clamped);
  const gp::KnotState k = gp::ReadKnotState(parameters[0], parameters[1], parameters[2]);
  const gp::KnotState k1 = gp::ReadKnotState(parameters[3], parameters[4], parameters[5]);
  gp::StateJacobian* J_k = knot_jacobians ? &out->J_k : nullptr;
  gp::StateJacobian* J_k1 = knot_jacobians ? &out->J_k1 : nullptr;
  if (rate && !clamped) {
    interpolator.StateRows(k, k1, rows, &out->x, J_k, J_k1, &out->rate);
  } else {
    interpolator.StateRows(k, k1, rows, &out->x, J_k, J_k1);
    out->rate.setZero();
  }
  const double T = t_k1 - t_k;
  out->s = (tau - t_k) / T;
  out->ds_ddelta = clamped ? 0.0 : 1.0 / T;
}

}  // namespace internal
}  // namespace ctlio::imu
