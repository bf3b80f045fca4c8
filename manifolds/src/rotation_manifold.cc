#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio {

void RotationManifold::Store(const Mat3& C, double* x) {
  const Eigen::Quaterniond q(C);
  x[0] = q.x();
  x[1] = q.y();
  x[2] = q.z();
  x[3] = q.w();
}

bool RotationManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Quaterniond q =
      (so3::ExpQuaternion(Eigen::Map<const Vec3>(delta)) * Quaternion(x)).normalized();
  x_plus_delta[0] = q.x();
  x_plus_delta[1] = q.y();
  x_plus_delta[2] = q.z();
  x_plus_delta[3] = q.w();
  return true;
}

// d(Exp(δ) ⊗ q)/dδ at δ = 0 = ½·[[q_w I − q_v^], [−q_vᵀ]] (right-multiplication
// matrix of q, first three columns, times d Exp/dδ = [½I; 0]).
bool RotationManifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Quaterniond q = Quaternion(x);
  Eigen::Map<PlusJacobianMatrix> J(jacobian);
  J.topRows<3>() = 0.5 * (q.w() * Mat3::Identity() - so3::Hat(q.vec()));
  J.bottomRows<1>() = -0.5 * q.vec().transpose();
  return true;
}

bool RotationManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Vec3>{y_minus_x} = so3::LogQuaternion(Quaternion(y) * Quaternion(x).conjugate());
  return true;
}

// d Log(y ⊗ x*)/dy at y = x = [2I, 0]·(right-multiplication matrix of x*).
RotationManifold::LiftMatrix RotationManifold::Lift(const double* x) {
  const Eigen::Quaterniond q = Quaternion(x);
  LiftMatrix L;
  L.leftCols<3>() = 2.0 * (q.w() * Mat3::Identity() + so3::Hat(q.vec()));
  L.rightCols<1>() = -2.0 * q.vec();
  return L;
}

bool RotationManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<LiftMatrix>{jacobian} = Lift(x);
  return true;
}

}  // namespace ctlio
