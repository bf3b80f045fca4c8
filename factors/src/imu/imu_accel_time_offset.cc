#include "ctlio/factors/imu/imu_accel_time_offset.h"

#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::imu {

using internal::WriteKnotJacobians;

ImuAccelMeasurementWithTimeOffset::ImuAccelMeasurementWithTimeOffset(
    const gp::SingerModel<6>& model, double t_k, double t_k1, double stamp, const Vec3& accel,
    const Mat3& covariance, double gravity, AccelModel accel_model, const ImuMounting& mounting)
    : model_(model),
      t_k_(t_k),
      t_k1_(t_k1),
      stamp_(stamp),
      residual_(accel, covariance, gravity, accel_model, mounting) {
  // The interval's checks (t_k < t_{k+1}), once.
  gp::GpInterpolator(model, t_k, t_k1, t_k);
}

bool ImuAccelMeasurementWithTimeOffset::Evaluate(double const* const* parameters, double* residuals,
                                                 double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const Mat3 C_mi = RotationManifold::Rotation(parameters[8]);
  const double delta = parameters[9][0];
  const bool need_knots = internal::NeedsKnotJacobians(jacobians);
  const bool need_rate = jacobians != nullptr && jacobians[9] != nullptr;
  internal::TimeShiftedState st;
  internal::InterpolateShifted(model_, t_k_, t_k1_, stamp_, delta, residual_.rows(), parameters,
                               need_knots, need_rate, &st);
  const double s = st.s;
  const Vec3 ba = (1.0 - s) * b_k.head<3>() + s * b_k1.head<3>();
  internal::AccelResidual::Linearisation lin;
  Eigen::Map<Vec3>{residuals} =
      residual_.Evaluate(st.x, C_mi, ba, jacobians != nullptr ? &lin : nullptr);
  if (jacobians == nullptr) return true;

  if (need_knots) {
    WriteKnotJacobians(residual_.Chain(lin, st.J_k), parameters[0], jacobians[0], jacobians[1],
                       jacobians[2]);
    WriteKnotJacobians(residual_.Chain(lin, st.J_k1), parameters[3], jacobians[3], jacobians[4],
                       jacobians[5]);
  }
  internal::WriteBiasJacobians(residual_.sqrt_information(), s, 0, jacobians[6], jacobians[7]);
  if (jacobians[8] != nullptr) {
    LiftRotationJacobian<3>(residual_.GravityJacobian(lin), parameters[8], jacobians[8]);
  }
  if (need_rate) {
    // ∂e/∂δ = D·ẋ(τ) − S·db_a/dτ.
    Eigen::Map<Vec3>{jacobians[9]} =
        residual_.Chain(lin, st.rate) -
        st.ds_ddelta * residual_.sqrt_information() * (b_k1.head<3>() - b_k.head<3>());
  }
  return true;
}

}  // namespace ctlio::imu
