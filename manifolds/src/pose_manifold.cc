#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

void PoseManifold::Store(const SE3& T, double* x) {
  Eigen::Map<Vec3>{x} = T.translation();
  RotationManifold::Store(T.rotation(), x + 3);
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Vec3> rho(delta);
  const Eigen::Map<const Vec3> phi(delta + 3);
  const Eigen::Quaterniond dq = so3::ExpQuaternion(phi);
  const Eigen::Quaterniond q = (dq * RotationManifold::Quaternion(x + 3)).normalized();
  // Exp(δ)·T = [Exp(φ)C, Exp(φ)r + J(φ)ρ].
  Eigen::Map<Vec3>{x_plus_delta} =
      dq.toRotationMatrix() * Eigen::Map<const Vec3>(x) + so3::LeftJacobian(phi) * rho;
  x_plus_delta[3] = q.x();
  x_plus_delta[4] = q.y();
  x_plus_delta[5] = q.z();
  x_plus_delta[6] = q.w();
  return true;
}

// [[I, −r^], [0, dq/dφ]].
bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<PlusJacobianMatrix> J(jacobian);
  J.setZero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.topRightCorner<3, 3>() = -so3::Hat(Eigen::Map<const Vec3>(x));
  RotationManifold::PlusJacobianMatrix Jq;
  RotationManifold().PlusJacobian(x + 3, Jq.data());
  J.bottomRightCorner<4, 3>() = Jq;
  return true;
}

// Log(Y·X⁻¹) with Y·X⁻¹ = [C_y C_xᵀ, r_y − C_y C_xᵀ r_x]. The relative
// quaternion is normalised so that Minus is invariant to the scale of y's
// quaternion, as MinusJacobian assumes.
bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Quaterniond dq =
      (RotationManifold::Quaternion(y + 3) * RotationManifold::Quaternion(x + 3).conjugate())
          .normalized();
  const Vec3 phi = so3::LogQuaternion(dq);
  const Vec3 t = Eigen::Map<const Vec3>(y) - dq.toRotationMatrix() * Eigen::Map<const Vec3>(x);
  Eigen::Map<Vec3>{y_minus_x} = so3::LeftJacobianInverse(phi) * t;
  Eigen::Map<Vec3>{y_minus_x + 3} = phi;
  return true;
}

// d Log(Y·X⁻¹)/dY at Y = X: dφ = L_q dq_y and dρ = dr_y + r_x^ dφ.
PoseManifold::LiftMatrix PoseManifold::Lift(const double* x) {
  const RotationManifold::LiftMatrix Lq = RotationManifold::Lift(x + 3);
  LiftMatrix L = LiftMatrix::Zero();
  L.topLeftCorner<3, 3>().setIdentity();
  L.topRightCorner<3, 4>() = so3::Hat(Eigen::Map<const Vec3>(x)) * Lq;
  L.bottomRightCorner<3, 4>() = Lq;
  return L;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<LiftMatrix>{jacobian} = Lift(x);
  return true;
}

}  // namespace ctlio
