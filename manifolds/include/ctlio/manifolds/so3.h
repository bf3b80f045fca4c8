// SO(3): the rotation group with the rotation-vector tangent of SPEC §1.
//
// Conventions: C = Exp(φ) = exp(φ^); the left Jacobian J(φ) satisfies
// Exp(φ + δ) ≈ Exp(J(φ)·δ)·Exp(φ). Every coefficient that cancels
// catastrophically near θ = |φ| = 0 is evaluated by its Taylor series below
// kSmallAngle, and J⁻¹ is written with cot(θ/2) so that it stays finite at
// θ = π (Log never returns θ > π).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>

#include "ctlio/manifolds/types.h"

namespace ctlio::so3 {

// Below this angle the closed forms lose more than ~5e-15 relative precision
// to cancellation (θ − sinθ ≈ θ³/6, 1 − (θ/2)cot(θ/2) ≈ θ²/12); the series
// used instead run to θ¹² or further, so their truncation error is < 1e-16.
inline constexpr double kSmallAngle = 0.5;

// Σ c[k]·x^k by Horner's rule (x is θ² in every series below).
template <std::size_t N>
constexpr double Series(double x, const double (&c)[N]) {
  double sum = c[N - 1];
  for (std::size_t k = N - 1; k-- > 0;) sum = sum * x + c[k];
  return sum;
}

inline Mat3 Hat(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

inline Vec3 Vee(const Mat3& m) { return Vec3(m(2, 1), m(0, 2), m(1, 0)); }

// Coefficients of φ^ and φ^φ^ shared by Exp and J, as functions of θ².
// a = sinθ/θ, b = (1−cosθ)/θ², c = (θ−sinθ)/θ³.
struct RodriguesCoefficients {
  double a, b, c;
  explicit RodriguesCoefficients(double theta2) {
    if (theta2 < kSmallAngle * kSmallAngle) {
      // Σ(−1)ⁿθ²ⁿ/(2n+1)!, Σ(−1)ⁿθ²ⁿ/(2n+2)!, Σ(−1)ⁿθ²ⁿ/(2n+3)!.
      constexpr double ka[] = {
          1.0,          -1.0 / 6,        1.0 / 120,        -1.0 / 5040,
          1.0 / 362880, -1.0 / 39916800, 1.0 / 6227020800, -1.0 / 1307674368000};
      constexpr double kb[] = {
          1.0 / 2,       -1.0 / 24,        1.0 / 720,         -1.0 / 40320,
          1.0 / 3628800, -1.0 / 479001600, 1.0 / 87178291200, -1.0 / 20922789888000};
      constexpr double kc[] = {
          1.0 / 6,        -1.0 / 120,        1.0 / 5040,          -1.0 / 362880,
          1.0 / 39916800, -1.0 / 6227020800, 1.0 / 1307674368000, -1.0 / 355687428096000};
      a = Series(theta2, ka);
      b = Series(theta2, kb);
      c = Series(theta2, kc);
    } else {
      const double theta = std::sqrt(theta2);
      const double s = std::sin(theta);
      const double half_s = std::sin(0.5 * theta);
      a = s / theta;
      b = 2.0 * half_s * half_s / theta2;
      c = (theta - s) / (theta2 * theta);
    }
  }
};

// e(θ) = (θ² + 2cosθ − 2)/(2θ⁴) = Σₙ(−1)ⁿθ²ⁿ/(2n+4)!, the next member of the a, b, c family
// above: the φ^φ^ coefficient of ∫₀¹(1−α)Exp(αφ)dα (preintegration) and of the SE(3) Q block
// (Barfoot eq. 7.86). Below kSmallAngle the series (to θ¹⁴) is used: its truncation error is
// < θ¹⁶/20! < 7e-24, i.e. < 2e-22 relative (the result is within 1 ulp). Above, the closed form
// cancels (its numerator ≈ θ⁴/12 out of terms of size 2): relative error < 1e-13 for every
// θ ≥ 0.5 (largest just above the switch, 5e-14 on a fine grid up to π). Tested on both sides
// against a long-double reference (test/manifolds/lie_group_test.cc).
inline double RodriguesCoefficientE(double theta2) {
  if (theta2 < kSmallAngle * kSmallAngle) {
    constexpr double ke[] = {
        1.0 / 24,        -1.0 / 720,         1.0 / 40320,          -1.0 / 3628800,
        1.0 / 479001600, -1.0 / 87178291200, 1.0 / 20922789888000, -1.0 / 6402373705728000};
    return Series(theta2, ke);
  }
  return (theta2 + 2.0 * std::cos(std::sqrt(theta2)) - 2.0) / (2.0 * theta2 * theta2);
}

inline Mat3 Exp(const Vec3& phi) {
  const RodriguesCoefficients k(phi.squaredNorm());
  const Mat3 W = Hat(phi);
  return Mat3::Identity() + k.a * W + k.b * W * W;
}

inline Eigen::Quaterniond ExpQuaternion(const Vec3& phi) {
  const double theta = phi.norm();
  // sin(θ/2)/θ, with its series near 0.
  const double t2 = theta * theta;
  // No cancellation here; the series only avoids 0/0.
  constexpr double ks[] = {1.0 / 2, -1.0 / 48, 1.0 / 3840, -1.0 / 645120, 1.0 / 185794560};
  const double s = theta < 1e-2 ? Series(t2, ks) : std::sin(0.5 * theta) / theta;
  return Eigen::Quaterniond(std::cos(0.5 * theta), s * phi.x(), s * phi.y(), s * phi.z());
}

// Log of a unit quaternion: θ = 2·atan2(|v|, w) with w ≥ 0, accurate up to θ = π.
inline Vec3 LogQuaternion(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  const double w = q.w();
  double scale;  // θ/|v|
  if (n < 1e-8 * w) {
    const double x2 = (n / w) * (n / w);
    scale = (2.0 / w) * (1.0 - x2 / 3.0);
  } else {
    scale = 2.0 * std::atan2(n, w) / n;
  }
  return scale * q.vec();
}

inline Vec3 Log(const Mat3& C) { return LogQuaternion(Eigen::Quaterniond(C)); }

// Left Jacobian J(φ) = I + b·φ^ + c·φ^φ^ (Barfoot, State Estimation, eq. 7.77a).
inline Mat3 LeftJacobian(const Vec3& phi) {
  const RodriguesCoefficients k(phi.squaredNorm());
  const Mat3 W = Hat(phi);
  return Mat3::Identity() + k.b * W + k.c * W * W;
}

// (1 − (θ/2)·cot(θ/2))/θ²: the φ^φ^ coefficient of J⁻¹; finite on [0, π].
inline double LeftJacobianInverseCoefficient(double theta2) {
  if (theta2 < kSmallAngle * kSmallAngle) {
    // Σ_{n≥1} |B₂ₙ|/(2n)!·θ²ⁿ⁻² (Bernoulli numbers B₂ … B₁₆).
    constexpr double kd[] = {1.0 / 12,
                             1.0 / 720,
                             1.0 / 30240,
                             1.0 / 1209600,
                             1.0 / 47900160,
                             (691.0 / 2730) / 479001600,
                             (7.0 / 6) / 87178291200,
                             (3617.0 / 510) / 20922789888000};
    return Series(theta2, kd);
  }
  const double theta = std::sqrt(theta2);
  const double half = 0.5 * theta;
  return (1.0 - half * std::cos(half) / std::sin(half)) / theta2;
}

// J⁻¹(φ) = I − ½φ^ + d·φ^φ^ (Barfoot eq. 7.77b, cot form).
inline Mat3 LeftJacobianInverse(const Vec3& phi) {
  const Mat3 W = Hat(phi);
  return Mat3::Identity() - 0.5 * W + LeftJacobianInverseCoefficient(phi.squaredNorm()) * W * W;
}

// Right Jacobians: Exp(φ + δ) ≈ Exp(φ)·Exp(J_r(φ)·δ), J_r(φ) = J(−φ).
inline Mat3 RightJacobian(const Vec3& phi) { return LeftJacobian(-phi); }
inline Mat3 RightJacobianInverse(const Vec3& phi) { return LeftJacobianInverse(-phi); }

// Projects a nearly orthogonal matrix back onto SO(3).
inline Mat3 Normalize(const Mat3& C) {
  return Eigen::Quaterniond(C).normalized().toRotationMatrix();
}

}  // namespace ctlio::so3
