#include "ctlio/factors/imu/imu_gyro_time_offset.h"

namespace ctlio::imu {

using internal::WriteKnotJacobians;

ImuGyroMeasurementWithTimeOffset::ImuGyroMeasurementWithTimeOffset(const gp::SingerModel<6>& model,
                                                                   double t_k, double t_k1,
                                                                   double stamp, const Vec3& gyro,
                                                                   const Mat3& covariance,
                                                                   const ImuMounting& mounting)
    : model_(model), t_k_(t_k), t_k1_(t_k1), stamp_(stamp), residual_(gyro, covariance, mounting) {
  // The interval's checks (t_k < t_{k+1}), once.
  gp::GpInterpolator(model, t_k, t_k1, t_k);
}

bool ImuGyroMeasurementWithTimeOffset::Evaluate(double const* const* parameters, double* residuals,
                                                double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const double delta = parameters[8][0];
  const bool need_knots = internal::NeedsKnotJacobians(jacobians);
  const bool need_rate = jacobians != nullptr && jacobians[8] != nullptr;
  const unsigned rows = gp::kAngularVelocityRows;
  internal::TimeShiftedState st;
  internal::InterpolateShifted(model_, t_k_, t_k1_, stamp_, delta, rows, parameters, need_knots,
                               need_rate, &st);
  const double s = st.s;
  const Vec3 bg = (1.0 - s) * b_k.tail<3>() + s * b_k1.tail<3>();
  Eigen::Map<Vec3>{residuals} = residual_.Evaluate(st.x, bg);
  if (jacobians == nullptr) return true;

  if (need_knots) {
    WriteKnotJacobians(residual_.Chain(st.J_k), parameters[0], jacobians[0], jacobians[1],
                       jacobians[2]);
    WriteKnotJacobians(residual_.Chain(st.J_k1), parameters[3], jacobians[3], jacobians[4],
                       jacobians[5]);
  }
  internal::WriteBiasJacobians(residual_.sqrt_information(), s, 3, jacobians[6], jacobians[7]);
  if (need_rate) {
    // ∂e/∂δ = D·ẋ(τ) − S·db_g/dτ.
    Eigen::Map<Vec3>{jacobians[8]} =
        residual_.Chain(st.rate) -
        st.ds_ddelta * residual_.sqrt_information() * (b_k1.tail<3>() - b_k.tail<3>());
  }
  return true;
}

}  // namespace ctlio::imu
