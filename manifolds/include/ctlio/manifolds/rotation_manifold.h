// ceres::Manifold for SO(3) stored as a unit quaternion [qx, qy, qz, qw]
// (Eigen's coefficient order) with the rotation-vector tangent and the left
// perturbation of SPEC §1: Plus(q, δ) = Exp(δ) ⊗ q, Minus(y, x) = Log(y ⊗ x*).
//
// This is NOT ceres::EigenQuaternionManifold: that one uses a half-angle,
// right-perturbation tangent. Cost functions compute Jacobians with respect to
// the 3-vector δ and return ambient Jacobians J_tangent · Lift(q), where
// Lift(q) = MinusJacobian(q) satisfies Lift · PlusJacobian = I (the OKVIS way,
// SPEC §1); the solver, GradientChecker and Covariance then all see J_tangent.
#pragma once

#include <ceres/manifold.h>

#include "ctlio/manifolds/so3.h"

namespace ctlio {

class RotationManifold final : public ceres::Manifold {
 public:
  static constexpr int kAmbientSize = 4;
  static constexpr int kTangentSize = 3;
  using LiftMatrix = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
  using PlusJacobianMatrix = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;

  int AmbientSize() const override { return kAmbientSize; }
  int TangentSize() const override { return kTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  static Eigen::Quaterniond Quaternion(const double* x) {
    return Eigen::Quaterniond(x[3], x[0], x[1], x[2]);
  }
  static Mat3 Rotation(const double* x) { return Quaternion(x).normalized().toRotationMatrix(); }
  static void Store(const Mat3& C, double* x);

  // 3×4 matrix with Lift(q)·PlusJacobian(q) = I₃.
  static LiftMatrix Lift(const double* x);
};

}  // namespace ctlio
