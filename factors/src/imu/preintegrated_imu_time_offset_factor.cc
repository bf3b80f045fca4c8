#include "ctlio/factors/imu/preintegrated_imu_time_offset_factor.h"

#include <cmath>
#include <stdexcept>

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio::imu {

PreintegratedImuTimeOffsetFactor::PreintegratedImuTimeOffsetFactor(
    const PreintegratedImu& preintegrated, const Vec3& gravity, const PreintegrationEnds& ends,
    double offset_anchor)
    : pim_(preintegrated), gravity_(gravity), offset_anchor_(offset_anchor) {
  if (!(pim_.delta_t() > 0.0)) {
    throw std::invalid_argument("PreintegratedImuTimeOffsetFactor: empty preintegration (Δt = 0)");
  }
  if (!std::isfinite(offset_anchor) || !ends.accel_begin.allFinite() ||
      !ends.gyro_begin.allFinite() || !ends.accel_end.allFinite() || !ends.gyro_end.allFinite()) {
    throw std::invalid_argument(
        "PreintegratedImuTimeOffsetFactor: non-finite offset anchor or end readings");
  }
  sqrt_information_ = SqrtInformationFromCovariance<9>(
      pim_.covariance(),
      "PreintegratedImuTimeOffsetFactor: preintegrated covariance (are the noise densities zero?)");
  const Vec6& b = pim_.bias_hat();
  const Mat3& C_bs = pim_.C_body_sensor();
  const Vec3 w_a = C_bs * (ends.gyro_begin - b.tail<3>());
  const Vec3 f_a = C_bs * (ends.accel_begin - b.head<3>());
  const Vec3 w_b = C_bs * (ends.gyro_end - b.tail<3>());
  const Vec3 f_b = C_bs * (ends.accel_end - b.head<3>());
  const Mat3& dC = pim_.delta_rotation();
  rates_.rotation = w_a - dC * w_b;
  rates_.velocity = w_a.cross(pim_.delta_velocity()) + f_a - dC * f_b;
  rates_.position = w_a.cross(pim_.delta_position()) - pim_.delta_velocity() + f_a * pim_.delta_t();
}

bool PreintegratedImuTimeOffsetFactor::Evaluate(double const* const* parameters, double* residuals,
                                                double** jacobians) const {
  PreintegrationShift shift = rates_;
  shift.d = parameters[5][0] - offset_anchor_;
  double* d_offset = jacobians != nullptr ? jacobians[5] : nullptr;
  // ∂d/∂δ = 1: the derivative by d is the δ block's column.
  return internal::EvaluatePreintegrated(pim_, gravity_, sqrt_information_, &shift, parameters,
                                         residuals, jacobians, d_offset);
}

}  // namespace ctlio::imu
