#include "ctlio/factors/imu/imu_measurement.h"

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::imu {
namespace {

using internal::Row3x18;
using internal::WriteKnotJacobians;

// A state interpolation of a factor's own (not shared), asking for `rows`.
std::shared_ptr<gp::SharedStateInterpolation> OwnState(const gp::SingerModel<6>& model, double t_k,
                                                       double t_k1, double tau) {
  return std::make_shared<gp::SharedStateInterpolation>(model, t_k, t_k1, tau);
}

// Registers `rows` with a (possibly shared) state and returns it.
std::shared_ptr<gp::SharedStateInterpolation> WithRows(
    std::shared_ptr<gp::SharedStateInterpolation> state, unsigned rows) {
  state->AddRows(rows);
  return state;
}

}  // namespace

ImuGyroMeasurement::ImuGyroMeasurement(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                       double tau, const Vec3& gyro, const Mat3& covariance,
                                       const ImuMounting& mounting)
    : ImuGyroMeasurement(OwnState(model, t_k, t_k1, tau), gyro, covariance, mounting) {}

ImuGyroMeasurement::ImuGyroMeasurement(std::shared_ptr<gp::SharedStateInterpolation> state,
                                       const Vec3& gyro, const Mat3& covariance,
                                       const ImuMounting& mounting)
    : state_(WithRows(std::move(state), Rows())),
      s_(state_->fraction()),
      residual_(gyro, covariance, mounting) {}

bool ImuGyroMeasurement::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const bool need_knots = internal::NeedsKnotJacobians(jacobians);
  gp::SharedStateInterpolation::Result scratch;  // only the ϖ_ω rows are read
  const gp::SharedStateInterpolation::Result& interpolated =
      state_->State(parameters, Rows(), need_knots, &scratch);

  const Vec3 bg = (1.0 - s_) * b_k.tail<3>() + s_ * b_k1.tail<3>();
  Eigen::Map<Vec3>{residuals} = residual_.Evaluate(interpolated.x, bg);
  if (jacobians == nullptr) return true;

  if (need_knots) {
    WriteKnotJacobians(residual_.Chain(interpolated.J_k), parameters[0], jacobians[0], jacobians[1],
                       jacobians[2]);
    WriteKnotJacobians(residual_.Chain(interpolated.J_k1), parameters[3], jacobians[3],
                       jacobians[4], jacobians[5]);
  }
  internal::WriteBiasJacobians(residual_.sqrt_information(), s_, 3, jacobians[6], jacobians[7]);
  return true;
}

ImuAccelMeasurement::ImuAccelMeasurement(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                         double tau, const Vec3& accel, const Mat3& covariance,
                                         double gravity, AccelModel accel_model,
                                         const ImuMounting& mounting)
    : ImuAccelMeasurement(OwnState(model, t_k, t_k1, tau), accel, covariance, gravity, accel_model,
                          mounting) {}

ImuAccelMeasurement::ImuAccelMeasurement(std::shared_ptr<gp::SharedStateInterpolation> state,
                                         const Vec3& accel, const Mat3& covariance, double gravity,
                                         AccelModel accel_model, const ImuMounting& mounting)
    : state_(WithRows(std::move(state), Rows(accel_model, mounting))),
      s_(state_->fraction()),
      residual_(accel, covariance, gravity, accel_model, mounting) {}

bool ImuAccelMeasurement::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const Mat3 C_mi = RotationManifold::Rotation(parameters[8]);
  const bool need_knots = internal::NeedsKnotJacobians(jacobians);
  // Only the rows D reads (residual_.rows()) are read.
  gp::SharedStateInterpolation::Result scratch;
  const gp::SharedStateInterpolation::Result& interpolated =
      state_->State(parameters, residual_.rows(), need_knots, &scratch);

  const Vec3 ba = (1.0 - s_) * b_k.head<3>() + s_ * b_k1.head<3>();
  internal::AccelResidual::Linearisation lin;
  Eigen::Map<Vec3>{residuals} =
      residual_.Evaluate(interpolated.x, C_mi, ba, jacobians != nullptr ? &lin : nullptr);
  if (jacobians == nullptr) return true;

  if (need_knots) {
    WriteKnotJacobians(residual_.Chain(lin, interpolated.J_k), parameters[0], jacobians[0],
                       jacobians[1], jacobians[2]);
    WriteKnotJacobians(residual_.Chain(lin, interpolated.J_k1), parameters[3], jacobians[3],
                       jacobians[4], jacobians[5]);
  }
  internal::WriteBiasJacobians(residual_.sqrt_information(), s_, 0, jacobians[6], jacobians[7]);
  if (jacobians[8] != nullptr) {
    LiftRotationJacobian<3>(residual_.GravityJacobian(lin), parameters[8], jacobians[8]);
  }
  return true;
}

}  // namespace ctlio::imu
