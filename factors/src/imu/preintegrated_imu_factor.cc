#include "ctlio/factors/imu/preintegrated_imu_factor.h"

#include <stdexcept>

#include "ctlio/factors/priors/sqrt_information.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::imu {

PreintegratedImuFactor::PreintegratedImuFactor(const PreintegratedImu& preintegrated,
                                               const Vec3& gravity)
    : pim_(preintegrated), gravity_(gravity) {
  if (!(pim_.delta_t() > 0.0)) {
    throw std::invalid_argument("PreintegratedImuFactor: empty preintegration (Δt = 0)");
  }
  sqrt_information_ = SqrtInformationFromCovariance<9>(
      pim_.covariance(),
      "PreintegratedImuFactor: preintegrated covariance (are the noise densities zero?)");
}

bool PreintegratedImuFactor::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  return internal::EvaluatePreintegrated(pim_, gravity_, sqrt_information_, nullptr, parameters,
                                         residuals, jacobians, nullptr);
}

namespace internal {

bool EvaluatePreintegrated(const PreintegratedImu& pim, const Vec3& gravity,
                           const Mat9& sqrt_information, const PreintegrationShift* shift,
                           double const* const* parameters, double* residuals, double** jacobians,
                           double* d_shift) {
  const SE3 Ti = PoseManifold::Pose(parameters[0]);
  const Eigen::Map<const Vec3> vi(parameters[1]);
  const Eigen::Map<const Vec6> bi(parameters[2]);
  const SE3 Tj = PoseManifold::Pose(parameters[3]);
  const Eigen::Map<const Vec3> vj(parameters[4]);

  const Mat3& Ci = Ti.rotation();
  const Mat3& Cj = Tj.rotation();
  const Vec3& pi = Ti.translation();
  const Vec3& pj = Tj.translation();
  const double dt = pim.delta_t();
  const Mat3 CiT = Ci.transpose();

  const Vec6 db = bi - pim.bias_hat();
  const Vec3 phi_bg = pim.dR_dbg() * db.tail<3>();
  const Mat3 dC = pim.delta_rotation() * so3::Exp(phi_bg);
  // The shift's rotation Exp(d·k_R) sits left of ΔC(b): between ΔC(b)ᵀ and C_iᵀ in E, where the
  // Jacobians below by C_i, C_j and b_g do not see it.
  const Mat3 shifted_CiT = shift != nullptr ? so3::Exp(-shift->d * shift->rotation) * CiT : CiT;
  const Mat3 E = dC.transpose() * shifted_CiT * Cj;
  const Vec3 w = vj - vi - gravity * dt;
  const Vec3 u = pj - pi - vi * dt - 0.5 * gravity * dt * dt;

  Eigen::Matrix<double, 9, 1> e;
  e.segment<3>(0) = so3::Log(E);
  e.segment<3>(3) = CiT * w - pim.CorrectedVelocity(bi);
  e.segment<3>(6) = CiT * u - pim.CorrectedPosition(bi);
  if (shift != nullptr) {
    e.segment<3>(3) -= shift->d * shift->velocity;
    e.segment<3>(6) -= shift->d * shift->position;
  }
  Eigen::Map<Eigen::Matrix<double, 9, 1>>{residuals} = sqrt_information * e;

  const Mat3 Jr_inv = so3::RightJacobianInverse(e.segment<3>(0));
  if (d_shift != nullptr) {
    // ∂e_R/∂d = −J_r⁻¹(e_R)·Eᵀ·ΔC(b)ᵀ·k_R (the header of the time-offset factor).
    Eigen::Matrix<double, 9, 1> J;
    J.segment<3>(0) = -Jr_inv * E.transpose() * dC.transpose() * shift->rotation;
    J.segment<3>(3) = -shift->velocity;
    J.segment<3>(6) = -shift->position;
    Eigen::Map<Eigen::Matrix<double, 9, 1>>{d_shift} = sqrt_information * J;
  }
  if (jacobians == nullptr) return true;
  const Mat3 Jr_inv_CjT = Jr_inv * Cj.transpose();

  if (jacobians[0] != nullptr) {
    Eigen::Matrix<double, 9, 6> J = Eigen::Matrix<double, 9, 6>::Zero();
    J.block<3, 3>(0, 3) = -Jr_inv_CjT;
    J.block<3, 3>(3, 3) = CiT * so3::Hat(w);
    J.block<3, 3>(6, 0) = -CiT;
    J.block<3, 3>(6, 3) = CiT * so3::Hat(u + pi);
    LiftPoseJacobian<9>(sqrt_information * J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 9, 3> J = Eigen::Matrix<double, 9, 3>::Zero();
    J.block<3, 3>(3, 0) = -CiT;
    J.block<3, 3>(6, 0) = -CiT * dt;
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>>{jacobians[1]} = sqrt_information * J;
  }
  if (jacobians[2] != nullptr) {
    Mat96 J = -pim.bias_jacobian();
    J.block<3, 3>(0, 0).setZero();
    J.block<3, 3>(0, 3) = -Jr_inv * E.transpose() * so3::RightJacobian(phi_bg) * pim.dR_dbg();
    Eigen::Map<Eigen::Matrix<double, 9, 6, Eigen::RowMajor>>{jacobians[2]} = sqrt_information * J;
  }
  if (jacobians[3] != nullptr) {
    Eigen::Matrix<double, 9, 6> J = Eigen::Matrix<double, 9, 6>::Zero();
    J.block<3, 3>(0, 3) = Jr_inv_CjT;
    J.block<3, 3>(6, 0) = CiT;
    J.block<3, 3>(6, 3) = -CiT * so3::Hat(pj);
    LiftPoseJacobian<9>(sqrt_information * J, parameters[3], jacobians[3]);
  }
  if (jacobians[4] != nullptr) {
    Eigen::Matrix<double, 9, 3> J = Eigen::Matrix<double, 9, 3>::Zero();
    J.block<3, 3>(3, 0) = CiT;
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>>{jacobians[4]} = sqrt_information * J;
  }
  return true;
}

}  // namespace internal

}  // namespace ctlio::imu
