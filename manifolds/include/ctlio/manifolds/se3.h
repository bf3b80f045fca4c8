// SE(3) with the conventions of SPEC §1, in one place for all of ctlio.
//
//   ξ = [ρ; φ] (translation first), hat(ξ) = [[φ^, ρ], [0, 0]],
//   curlyhat(ξ) = [[φ^, ρ^], [0, φ^]], Ad(T) = [[C, r^C], [0, C]].
//   T_ab maps b-coordinates into a; perturbations act on the left:
//   T ← Exp(δ)·T. J(ξ) is the left Jacobian: Exp(ξ + δ) ≈ Exp(J(ξ)δ)·Exp(ξ).
#pragma once

#include <Eigen/Geometry>

#include "ctlio/manifolds/so3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio {

class SE3 {
 public:
  SE3() : C_(Mat3::Identity()), r_(Vec3::Zero()) {}
  SE3(const Mat3& C, const Vec3& r) : C_(C), r_(r) {}
  SE3(const Eigen::Quaterniond& q, const Vec3& r) : C_(q.normalized().toRotationMatrix()), r_(r) {}

  static SE3 Identity() { return SE3(); }

  const Mat3& rotation() const { return C_; }
  const Vec3& translation() const { return r_; }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(C_).normalized(); }

  SE3 operator*(const SE3& other) const { return SE3(C_ * other.C_, C_ * other.r_ + r_); }
  Vec3 operator*(const Vec3& p) const { return C_ * p + r_; }
  SE3 Inverse() const { return SE3(C_.transpose(), -(C_.transpose() * r_)); }

  Mat4 Matrix() const {
    Mat4 T = Mat4::Identity();
    T.topLeftCorner<3, 3>() = C_;
    T.topRightCorner<3, 1>() = r_;
    return T;
  }

  // Ad(T) = [[C, r^C], [0, C]]; Exp(Ad(T)ξ) = T·Exp(ξ)·T⁻¹.
  Mat6 Adjoint() const {
    Mat6 A = Mat6::Zero();
    A.topLeftCorner<3, 3>() = C_;
    A.topRightCorner<3, 3>() = so3::Hat(r_) * C_;
    A.bottomRightCorner<3, 3>() = C_;
    return A;
  }

  static SE3 Exp(const Vec6& xi);
  Vec6 Log() const;

 private:
  Mat3 C_;
  Vec3 r_;
};

namespace se3 {

inline Mat4 Hat(const Vec6& xi) {
  Mat4 m = Mat4::Zero();
  m.topLeftCorner<3, 3>() = so3::Hat(xi.tail<3>());
  m.topRightCorner<3, 1>() = xi.head<3>();
  return m;
}

inline Vec6 Vee(const Mat4& m) {
  Vec6 xi;
  xi << m.topRightCorner<3, 1>(), so3::Vee(m.topLeftCorner<3, 3>());
  return xi;
}

// The se(3) adjoint ξ^⋏ = [[φ^, ρ^], [0, φ^]] (Barfoot eq. 7.14).
inline Mat6 CurlyHat(const Vec6& xi) {
  Mat6 m = Mat6::Zero();
  m.topLeftCorner<3, 3>() = so3::Hat(xi.tail<3>());
  m.topRightCorner<3, 3>() = so3::Hat(xi.head<3>());
  m.bottomRightCorner<3, 3>() = m.topLeftCorner<3, 3>();
  return m;
}

// The off-diagonal block Q(ξ) of the SE(3) left Jacobian (Barfoot eq. 7.86),
// with its series below so3::kSmallAngle.
inline Mat3 LeftJacobianQ(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  const double t2 = phi.squaredNorm();
  double c1, c2, c3;
  if (t2 < so3::kSmallAngle * so3::kSmallAngle) {
    // c1 = Σ(−1)ⁿθ²ⁿ/(2n+3)!, c2 = Σ(−1)ⁿθ²ⁿ/(2n+4)!, c3 = Σ(−1)ⁿ(n+1)θ²ⁿ/(2n+5)!.
    c1 = so3::RodriguesCoefficients(t2).c;
    constexpr double k3[] = {
        1.0 / 120,        -2.0 / 5040,          3.0 / 362880,          -4.0 / 39916800,
        5.0 / 6227020800, -6.0 / 1307674368000, 7.0 / 355687428096000, -8.0 / 121645100408832000};
    c2 = so3::RodriguesCoefficientE(t2);
    c3 = so3::Series(t2, k3);
  } else {
    const double t = std::sqrt(t2);
    const double s = std::sin(t), c = std::cos(t);
    c1 = (t - s) / (t2 * t);
    c2 = so3::RodriguesCoefficientE(t2);
    c3 = (2.0 * t - 3.0 * s + t * c) / (2.0 * t2 * t2 * t);
  }
  const Mat3 P = so3::Hat(phi);
  const Mat3 R = so3::Hat(rho);
  const Mat3 PR = P * R, RP = R * P, PRP = PR * P, PP = P * P;
  return 0.5 * R + c1 * (PR + RP + PRP) + c2 * (PP * R + RP * P - 3.0 * PRP) +
         c3 * (PRP * P + PP * RP);
}

// 𝒥(ξ) = [[J, Q], [0, J]].
inline Mat6 LeftJacobian(const Vec6& xi) {
  Mat6 J = Mat6::Zero();
  const Mat3 Js = so3::LeftJacobian(xi.tail<3>());
  J.topLeftCorner<3, 3>() = Js;
  J.bottomRightCorner<3, 3>() = Js;
  J.topRightCorner<3, 3>() = LeftJacobianQ(xi);
  return J;
}

// 𝒥⁻¹(ξ) = [[J⁻¹, −J⁻¹QJ⁻¹], [0, J⁻¹]].
inline Mat6 LeftJacobianInverse(const Vec6& xi) {
  Mat6 Ji = Mat6::Zero();
  const Mat3 Jsi = so3::LeftJacobianInverse(xi.tail<3>());
  Ji.topLeftCorner<3, 3>() = Jsi;
  Ji.bottomRightCorner<3, 3>() = Jsi;
  Ji.topRightCorner<3, 3>() = -Jsi * LeftJacobianQ(xi) * Jsi;
  return Ji;
}

inline Mat6 RightJacobian(const Vec6& xi) { return LeftJacobian(-xi); }
inline Mat6 RightJacobianInverse(const Vec6& xi) { return LeftJacobianInverse(-xi); }

// d(T·p)/dδ for T ← Exp(δ)·T: [I, −(T·p)^] (Barfoot's (Tp)^⊙ for a point).
inline Eigen::Matrix<double, 3, 6> PointJacobian(const Vec3& transformed_point) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>().setIdentity();
  J.rightCols<3>() = -so3::Hat(transformed_point);
  return J;
}

}  // namespace se3

inline SE3 SE3::Exp(const Vec6& xi) {
  const Vec3 phi = xi.tail<3>();
  return SE3(so3::Exp(phi), so3::LeftJacobian(phi) * xi.head<3>());
}

inline Vec6 SE3::Log() const {
  Vec6 xi;
  xi.tail<3>() = so3::Log(C_);
  xi.head<3>() = so3::LeftJacobianInverse(xi.tail<3>()) * r_;
  return xi;
}

}  // namespace ctlio
