#include "ctlio/factors/imu/imu_measurement.h"

#include <stdexcept>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/priors/sqrt_information.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::imu {
namespace {

using Row3x18 = Eigen::Matrix<double, 3, 18>;
using Jac3x6 = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;

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

// Writes D·J (3×18) of one knot into its pose (lifted), ϖ and ϖ̇ blocks.
void WriteKnotJacobians(const Row3x18& DJ, const double* pose, double* j_pose, double* j_vel,
                        double* j_acc) {
  if (j_pose != nullptr) LiftPoseJacobian<3>(DJ.leftCols<6>(), pose, j_pose);
  if (j_vel != nullptr) Eigen::Map<Jac3x6>{j_vel} = DJ.middleCols<6>(6);
  if (j_acc != nullptr) Eigen::Map<Jac3x6>{j_acc} = DJ.rightCols<6>();
}

}  // namespace

Mat3 SqrtInformation(const Mat3& covariance) {
  return SqrtInformationFromCovariance<3>(covariance, "IMU measurement covariance");
}

ImuGyroMeasurement::ImuGyroMeasurement(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                       double tau, const Vec3& gyro, const Mat3& covariance,
                                       const ImuMounting& mounting)
    : ImuGyroMeasurement(OwnState(model, t_k, t_k1, tau), gyro, covariance, mounting) {}

ImuGyroMeasurement::ImuGyroMeasurement(std::shared_ptr<gp::SharedStateInterpolation> state,
                                       const Vec3& gyro, const Mat3& covariance,
                                       const ImuMounting& mounting)
    : state_(WithRows(std::move(state), Rows())),
      s_(state_->fraction()),
      gyro_(gyro),
      sqrt_information_(SqrtInformation(covariance)),
      C_ir_(mounting.C_ri.transpose()),
      S_C_ir_(sqrt_information_ * C_ir_),
      rotated_(mounting.HasRotation()) {}

bool ImuGyroMeasurement::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const bool need_knots =
      jacobians != nullptr &&
      (jacobians[0] != nullptr || jacobians[1] != nullptr || jacobians[2] != nullptr ||
       jacobians[3] != nullptr || jacobians[4] != nullptr || jacobians[5] != nullptr);
  gp::SharedStateInterpolation::Result scratch;  // only the ϖ_ω rows are read
  const gp::SharedStateInterpolation::Result& interpolated =
      state_->State(parameters, Rows(), need_knots, &scratch);
  const gp::KnotState& x = interpolated.x;
  const gp::StateJacobian& J_k = interpolated.J_k;
  const gp::StateJacobian& J_k1 = interpolated.J_k1;

  const Vec3 bg = (1.0 - s_) * b_k.tail<3>() + s_ * b_k1.tail<3>();
  const Vec3 w_imu = rotated_ ? Vec3(C_ir_ * x.velocity.tail<3>()) : Vec3(x.velocity.tail<3>());
  Eigen::Map<Vec3>{residuals} = sqrt_information_ * (gyro_ + w_imu - bg);
  if (jacobians == nullptr) return true;

  if (need_knots) {
    // D = [0 … C_ir at ϖ_ω … 0]: rows 9–11 of the state Jacobians.
    const Row3x18 DJ_k = S_C_ir_ * J_k.middleRows<3>(9);
    const Row3x18 DJ_k1 = S_C_ir_ * J_k1.middleRows<3>(9);
    WriteKnotJacobians(DJ_k, parameters[0], jacobians[0], jacobians[1], jacobians[2]);
    WriteKnotJacobians(DJ_k1, parameters[3], jacobians[3], jacobians[4], jacobians[5]);
  }
  for (int i = 0; i < 2; ++i) {
    if (jacobians[6 + i] == nullptr) continue;
    Eigen::Map<Jac3x6> J{jacobians[6 + i]};
    J.leftCols<3>().setZero();
    J.rightCols<3>() = -(i == 0 ? 1.0 - s_ : s_) * sqrt_information_;
  }
  return true;
}

unsigned ImuAccelMeasurement::Rows(AccelModel accel_model, const ImuMounting& mounting) {
  const bool exact = accel_model == AccelModel::kSpecificForce;
  return gp::kRotationRows | gp::kLinearAccelerationRows |
         (exact ? gp::kLinearVelocityRows | gp::kAngularVelocityRows : 0u) |
         (mounting.HasLeverArm() ? gp::kAngularVelocityRows | gp::kAngularAccelerationRows : 0u);
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
      accel_(accel),
      sqrt_information_(SqrtInformation(covariance)),
      gravity_i_(0.0, 0.0, -gravity),
      accel_model_(accel_model),
      C_ir_(mounting.C_ri.transpose()),
      S_C_ir_(sqrt_information_ * C_ir_),
      rotated_(mounting.HasRotation()),
      lever_arm_(mounting.lever_arm),
      lever_arm_nonzero_(mounting.HasLeverArm()),
      rows_(Rows(accel_model, mounting)) {}

bool ImuAccelMeasurement::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const Mat3 C_mi = RotationManifold::Rotation(parameters[8]);
  bool need_knots = false;
  if (jacobians != nullptr) {
    for (int i = 0; i < 6; ++i) need_knots = need_knots || jacobians[i] != nullptr;
  }
  const bool exact = accel_model_ == AccelModel::kSpecificForce;
  const bool lever = lever_arm_nonzero_;
  // Only the rows D reads (below, rows_) are read.
  gp::SharedStateInterpolation::Result scratch;
  const gp::SharedStateInterpolation::Result& interpolated =
      state_->State(parameters, rows_, need_knots, &scratch);
  const gp::KnotState& x = interpolated.x;
  const gp::StateJacobian& J_k = interpolated.J_k;
  const gp::StateJacobian& J_k1 = interpolated.J_k1;

  const Mat3& C = x.pose.rotation();  // C_rm(τ)
  const Vec3 g_m = C_mi * gravity_i_;
  const Vec3 g_r = C * g_m;
  const Vec3 w_v = x.velocity.head<3>(), w_w = x.velocity.tail<3>();
  const Vec3 ba = (1.0 - s_) * b_k.head<3>() + s_ * b_k1.head<3>();
  // e = f_m + C_ir e_r − b_a, e_r the robot-frame terms (header), summed in this order so that
  // the default mounting reproduces the robot-frame residual to the last bit.
  const auto to_imu = [this](const Vec3& v) { return rotated_ ? Vec3(C_ir_ * v) : v; };
  Vec3 e = accel_ + to_imu(x.acceleration.head<3>()) + to_imu(g_r) - ba;
  if (exact) e -= to_imu(w_w.cross(w_v));
  if (lever) {
    e -= to_imu(lever_arm_.cross(x.acceleration.tail<3>()) + w_w.cross(w_w.cross(lever_arm_)));
  }
  Eigen::Map<Vec3>{residuals} = sqrt_information_ * e;
  if (jacobians == nullptr) return true;

  if (need_knots) {
    // D·J = C_ir [−(g_r)^·J[δφ rows] + J[ϖ̇_v rows] (− ϖ_ω^ J[ϖ_v rows] + ϖ_v^ J[ϖ_ω rows])
    //             (− p^ J[ϖ̇_ω rows] + ((ϖ_ω×p)^ + ϖ_ω^ p^) J[ϖ_ω rows])].
    const Mat3 G = -so3::Hat(g_r);
    Mat3 W = exact ? Mat3(so3::Hat(w_v)) : Mat3::Zero();  // ∂e_r/∂ϖ_ω
    if (lever) W += so3::Hat(w_w.cross(lever_arm_)) + so3::Hat(w_w) * so3::Hat(lever_arm_);
    const auto chain = [&](const gp::StateJacobian& J) {
      Row3x18 DJ = J.middleRows<3>(12);
      DJ.noalias() += G * J.middleRows<3>(3);
      if (exact) DJ.noalias() -= so3::Hat(w_w) * J.middleRows<3>(6);
      if (exact || lever) DJ.noalias() += W * J.middleRows<3>(9);
      if (lever) DJ.noalias() -= so3::Hat(lever_arm_) * J.middleRows<3>(15);
      return Row3x18(S_C_ir_ * DJ);
    };
    WriteKnotJacobians(chain(J_k), parameters[0], jacobians[0], jacobians[1], jacobians[2]);
    WriteKnotJacobians(chain(J_k1), parameters[3], jacobians[3], jacobians[4], jacobians[5]);
  }
  for (int i = 0; i < 2; ++i) {
    if (jacobians[6 + i] == nullptr) continue;
    Eigen::Map<Jac3x6> J{jacobians[6 + i]};
    J.leftCols<3>() = -(i == 0 ? 1.0 - s_ : s_) * sqrt_information_;
    J.rightCols<3>().setZero();
  }
  if (jacobians[8] != nullptr) {
    const Mat3 J_psi = -S_C_ir_ * C * so3::Hat(g_m);
    LiftRotationJacobian<3>(J_psi, parameters[8], jacobians[8]);
  }
  return true;
}

}  // namespace ctlio::imu
