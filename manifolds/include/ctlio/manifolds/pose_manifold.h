// ceres::Manifold for SE(3), the pose of every knot.
//
// Storage (ambient, 7 doubles): [rx, ry, rz, qx, qy, qz, qw] — the translation
// r of T = [C, r] followed by the unit quaternion of C in Eigen's order.
// Tangent (6): ξ = [ρ; φ] with the left perturbation of SPEC §1:
//   Plus(T, δ) = Exp(δ)·T,   Minus(Y, X) = Log(Y·X⁻¹).
//
// Cost functions on a pose compute their Jacobian J_tangent with respect to δ
// and write the ambient Jacobian J_tangent · Lift(T) (LiftPoseJacobian below).
// Lift(T) = MinusJacobian(T) and Lift·PlusJacobian = I₆, so the solver (which
// multiplies by PlusJacobian), GradientChecker and Covariance all see exactly
// J_tangent. Never write tangent Jacobians into padded ambient columns.
#pragma once

#include <ceres/manifold.h>

#include "ctlio/manifolds/rotation_manifold.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio {

class PoseManifold final : public ceres::Manifold {
 public:
  static constexpr int kAmbientSize = 7;
  static constexpr int kTangentSize = 6;
  using LiftMatrix = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
  using PlusJacobianMatrix = Eigen::Matrix<double, 7, 6, Eigen::RowMajor>;

  int AmbientSize() const override { return kAmbientSize; }
  int TangentSize() const override { return kTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  static SE3 Pose(const double* x) {
    return SE3(RotationManifold::Rotation(x + 3), Vec3(x[0], x[1], x[2]));
  }
  static void Store(const SE3& T, double* x);

  // 6×7 matrix with Lift(T)·PlusJacobian(T) = I₆.
  static LiftMatrix Lift(const double* x);
};

// Writes J_tangent · Lift(x) into a row-major ambient Jacobian (Ceres layout).
// J_tangent has `Rows` rows and 6 columns.
template <int Rows, typename Derived>
void LiftPoseJacobian(const Eigen::MatrixBase<Derived>& jacobian_tangent, const double* x,
                      double* jacobian_ambient) {
  // Lift = [[I, r^·L_q], [0, L_q]], so J·Lift = [J_ρ, (J_ρ·r^ + J_φ)·L_q]: a third of the
  // flops of the dense Rows×6 by 6×7 product.
  Eigen::Map<Eigen::Matrix<double, Rows, 7, Eigen::RowMajor>> out(jacobian_ambient);
  const Eigen::Matrix<double, Rows, 3> j_rho = jacobian_tangent.template leftCols<3>();
  const Eigen::Matrix<double, Rows, 3> j_phi =
      j_rho * so3::Hat(Eigen::Map<const Vec3>(x)) + jacobian_tangent.template rightCols<3>();
  out.template leftCols<3>() = j_rho;
  out.template rightCols<4>().noalias() = j_phi * RotationManifold::Lift(x + 3);
}

// Same for a rotation parameter block (3 tangent columns, 4 ambient).
template <int Rows, typename Derived>
void LiftRotationJacobian(const Eigen::MatrixBase<Derived>& jacobian_tangent, const double* x,
                          double* jacobian_ambient) {
  Eigen::Map<Eigen::Matrix<double, Rows, 4, Eigen::RowMajor>> out(jacobian_ambient);
  out.noalias() = jacobian_tangent * RotationManifold::Lift(x);
}

}  // namespace ctlio
