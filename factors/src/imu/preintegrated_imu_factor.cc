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
  const SE3 Ti = PoseManifold::Pose(parameters[0]);
  const Eigen::Map<const Vec3> vi(parameters[1]);
  const Eigen::Map<const Vec6> bi(parameters[2]);
  const SE3 Tj = PoseManifold::Pose(parameters[3]);
  const Eigen::Map<const Vec3> vj(parameters[4]);

  const Mat3& Ci = Ti.rotation();
  const Mat3& Cj = Tj.rotation();
  const Vec3& pi = Ti.translation();
  const Vec3& pj = Tj.translation();
  const double dt = pim_.delta_t();
  const Mat3 CiT = Ci.transpose();

  const Vec6 db = bi - pim_.bias_hat();
  const Vec3 phi_bg = pim_.dR_dbg() * db.tail<3>();
  const Mat3 dC = pim_.delta_rotation() * so3::Exp(phi_bg);
  const Mat3 E = dC.transpose() * CiT * Cj;
  const Vec3 w = vj - vi - gravity_ * dt;
  const Vec3 u = pj - pi - vi * dt - 0.5 * gravity_ * dt * dt;

  Eigen::Matrix<double, 9, 1> e;
  e.segment<3>(0) = so3::Log(E);
  e.segment<3>(3) = CiT * w - pim_.CorrectedVelocity(bi);
  e.segment<3>(6) = CiT * u - pim_.CorrectedPosition(bi);
  Eigen::Map<Eigen::Matrix<double, 9, 1>>{residuals} = sqrt_information_ * e;

  if (jacobians == nullptr) return true;
  const Mat3 Jr_inv = so3::RightJacobianInverse(e.segment<3>(0));
  const Mat3 Jr_inv_CjT = Jr_inv * Cj.transpose();

  if (jacobians[0] != nullptr) {
    Eigen::Matrix<double, 9, 6> J = Eigen::Matrix<double, 9, 6>::Zero();
    J.block<3, 3>(0, 3) = -Jr_inv_CjT;
    J.block<3, 3>(3, 3) = CiT * so3::Hat(w);
    J.block<3, 3>(6, 0) = -CiT;
    J.block<3, 3>(6, 3) = CiT * so3::Hat(u + pi);
    LiftPoseJacobian<9>(sqrt_information_ * J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 9, 3> J = Eigen::Matrix<double, 9, 3>::Zero();
    J.block<3, 3>(3, 0) = -CiT;
    J.block<3, 3>(6, 0) = -CiT * dt;
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>>{jacobians[1]} = sqrt_information_ * J;
  }
  if (jacobians[2] != nullptr) {
    Mat96 J = -pim_.bias_jacobian();
    J.block<3, 3>(0, 0).setZero();
    J.block<3, 3>(0, 3) = -Jr_inv * E.transpose() * so3::RightJacobian(phi_bg) * pim_.dR_dbg();
    Eigen::Map<Eigen::Matrix<double, 9, 6, Eigen::RowMajor>>{jacobians[2]} = sqrt_information_ * J;
  }
  if (jacobians[3] != nullptr) {
    Eigen::Matrix<double, 9, 6> J = Eigen::Matrix<double, 9, 6>::Zero();
    J.block<3, 3>(0, 3) = Jr_inv_CjT;
    J.block<3, 3>(6, 0) = CiT;
    J.block<3, 3>(6, 3) = -CiT * so3::Hat(pj);
    LiftPoseJacobian<9>(sqrt_information_ * J, parameters[3], jacobians[3]);
  }
  if (jacobians[4] != nullptr) {
    Eigen::Matrix<double, 9, 3> J = Eigen::Matrix<double, 9, 3>::Zero();
    J.block<3, 3>(3, 0) = CiT;
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>>{jacobians[4]} = sqrt_information_ * J;
  }
  return true;
}

}  // namespace ctlio::imu
