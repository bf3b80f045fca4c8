// SO(3)/SE(3) module: identities to machine precision, near φ = 0 and |φ| = π.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ctlio/manifolds/se3.h"

namespace ctlio {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

// Rotation angles that exercise every branch: tiny, around the series switch,
// generic, and within 1e-6 of π.
double SampleAngle(std::mt19937& rng, int i) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  switch (i % 5) {
    case 0:
      return std::pow(10.0, -12.0 + 11.0 * u(rng));  // 1e-12 … 0.1
    case 1:
      return so3::kSmallAngle * (1.0 + 0.02 * (u(rng) - 0.5));  // series switch
    case 2:
      return kPi * u(rng);
    case 3:
      return kPi - 1e-6 * u(rng);  // |φ| near π
    default:
      return kPi - std::pow(10.0, -9.0 + 8.0 * u(rng));
  }
}

Vec6 SampleTwist(std::mt19937& rng, int i) {
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Vec6 xi;
  xi.head<3>() = Vec3(u(rng), u(rng), u(rng));
  xi.tail<3>() = SampleAngle(rng, i) * RandomUnit(rng);
  return xi;
}

TEST(So3, HatVeeRoundTripAndCrossProduct) {
  const Vec3 a(0.3, -1.2, 2.0), b(-0.7, 0.1, 0.4);
  EXPECT_TRUE(so3::Vee(so3::Hat(a)).isApprox(a));
  EXPECT_LT((so3::Hat(a) * b - a.cross(b)).norm(), 1e-15);
}

TEST(Se3, HatVeeRoundTrip) {
  Vec6 xi;
  xi << 1, 2, 3, 0.4, -0.5, 0.6;
  EXPECT_EQ(se3::Vee(se3::Hat(xi)), xi);
}

TEST(Se3, ExpLogRoundTripOnTenThousandPosesIncludingNearPi) {
  std::mt19937 rng(7);
  double worst = 0.0;
  for (int i = 0; i < 10000; ++i) {
    const SE3 T = SE3::Exp(SampleTwist(rng, i));
    const SE3 T2 = SE3::Exp(T.Log());
    worst = std::max(worst, (T.Matrix() - T2.Matrix()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(Se3, LogExpReturnsTheTwistBelowPi) {
  std::mt19937 rng(8);
  for (int i = 0; i < 5000; ++i) {
    const Vec6 xi = SampleTwist(rng, i);
    const Vec6 back = SE3::Exp(xi).Log();
    // Near π the rotation angle is ill-conditioned (dθ ~ ε/sin θ), the
    // translation more so; elsewhere the round trip is exact.
    const double tol = xi.tail<3>().norm() > kPi - 1e-3 ? 1e-6 : 1e-11;
    EXPECT_LT((back - xi).norm(), tol * std::max(1.0, xi.norm())) << xi.transpose();
  }
}

TEST(So3, TinyAnglesKeepFullRelativePrecision) {
  for (double theta : {1e-15, 1e-12, 1e-9, 1e-6, 1e-3}) {
    const Vec3 phi = theta * Vec3(0.6, -0.8, 0.0);
    const Vec3 back = so3::Log(so3::Exp(phi));
    EXPECT_LT((back - phi).norm(), 1e-14 * theta) << theta;
    const Mat3 C = so3::Exp(phi);
    EXPECT_LT((C.transpose() * C - Mat3::Identity()).norm(), 1e-15);
  }
}

TEST(Jacobians, LeftJacobianTimesInverseIsIdentity) {
  std::mt19937 rng(9);
  for (int i = 0; i < 5000; ++i) {
    const Vec6 xi = SampleTwist(rng, i);
    EXPECT_LT((so3::LeftJacobian(xi.tail<3>()) * so3::LeftJacobianInverse(xi.tail<3>()) -
               Mat3::Identity())
                  .norm(),
              1e-10);
    EXPECT_LT((se3::LeftJacobian(xi) * se3::LeftJacobianInverse(xi) - Mat6::Identity()).norm(),
              1e-10);
    EXPECT_TRUE(se3::LeftJacobianInverse(xi).allFinite());
  }
}

// The defining property Exp(ξ + δ) ≈ Exp(𝒥(ξ)δ)·Exp(ξ), by central differences.
TEST(Jacobians, LeftJacobianMatchesCentralDifferences) {
  std::mt19937 rng(10);
  const double h = 1e-6;
  for (int i = 0; i < 200; ++i) {
    Vec6 xi = SampleTwist(rng, i);
    if (xi.tail<3>().norm() > kPi - 1e-3) xi.tail<3>() *= 0.99;  // keep ξ ± h below π
    const SE3 T_inv = SE3::Exp(xi).Inverse();
    Mat6 numeric;
    for (int k = 0; k < 6; ++k) {
      const Vec6 e = Vec6::Unit(k) * h;
      numeric.col(k) =
          ((SE3::Exp(xi + e) * T_inv).Log() - (SE3::Exp(xi - e) * T_inv).Log()) / (2.0 * h);
    }
    EXPECT_LT((numeric - se3::LeftJacobian(xi)).norm(), 1e-7 * std::max(1.0, xi.norm()))
        << xi.transpose();
  }
}

// Series and closed forms agree across the switch: compare every coefficient
// with a long-double closed form (whose cancellation error there is < 1e-17);
// the bounds are a few ulps of each coefficient.
TEST(Jacobians, SeriesAndClosedFormAgreeAcrossTheSwitch) {
  for (double theta : {0.45, 0.4999999, 0.5, 0.5000001, 0.55}) {
    const long double t = theta, s = std::sin(t), c = std::cos(t), t2 = t * t;
    const so3::RodriguesCoefficients k(theta * theta);
    EXPECT_NEAR(k.a, static_cast<double>(s / t), 2e-16) << theta;
    EXPECT_NEAR(k.b, static_cast<double>((1.0L - c) / t2), 2e-16) << theta;
    EXPECT_NEAR(k.c, static_cast<double>((t - s) / (t2 * t)), 2e-16) << theta;
    const long double d = (1.0L - 0.5L * t / std::tan(0.5L * t)) / t2;
    EXPECT_NEAR(so3::LeftJacobianInverseCoefficient(theta * theta), static_cast<double>(d), 5e-16)
        << theta;
    // The SE(3) Q block, with ρ and φ of comparable size, against its closed form.
    const long double c2 = (t2 + 2.0L * c - 2.0L) / (2.0L * t2 * t2);
    const long double c3 = (2.0L * t - 3.0L * s + t * c) / (2.0L * t2 * t2 * t);
    Vec6 xi;
    xi.head<3>() = Vec3(0.3, -0.2, 0.4);
    xi.tail<3>() = theta * Vec3(1.0, 2.0, -2.0) / 3.0;
    const Mat3 P = so3::Hat(xi.tail<3>()), R = so3::Hat(xi.head<3>());
    const Mat3 expected = 0.5 * R +
                          static_cast<double>((t - s) / (t2 * t)) * (P * R + R * P + P * R * P) +
                          static_cast<double>(c2) * (P * P * R + R * P * P - 3.0 * P * R * P) +
                          static_cast<double>(c3) * (P * R * P * P + P * P * R * P);
    EXPECT_LT((se3::LeftJacobianQ(xi) - expected).cwiseAbs().maxCoeff(), 3e-16) << theta;
  }
}

// e(θ) = (θ² + 2cosθ − 2)/(2θ⁴) on both sides of the series switch, against a long-double
// reference (its own alternating series Σ(−1)ⁿθ²ⁿ/(2n+4)! to θ⁴⁰, whose truncation and rounding
// are < 1e-19 for θ ≤ π), with the error bounds stated in so3.h: within rounding (a few ulps)
// below the switch, 1e-13 relative at and above it.
TEST(Jacobians, RodriguesCoefficientEMatchesItsBoundOnBothSidesOfTheSwitch) {
  const auto reference = [](long double t2) {
    long double term = 1.0L / 24.0L, sum = 0.0L;
    for (int n = 0; n <= 20; ++n) {
      sum += term;
      term *= -t2 / ((2.0L * n + 5.0L) * (2.0L * n + 6.0L));
    }
    return sum;
  };
  for (double theta :
       {1e-8, 1e-3, 0.1, 0.3, 0.45, 0.4999999, 0.5, 0.5000001, 0.55, 1.0, 2.0, 3.0, 3.14159}) {
    const double e = so3::RodriguesCoefficientE(theta * theta);
    const double ref = static_cast<double>(reference(static_cast<long double>(theta) * theta));
    const double bound = theta < so3::kSmallAngle ? 4e-16 : 1e-13;
    EXPECT_LE(std::abs(e - ref), bound * std::abs(ref)) << "theta " << theta;
  }
  // The two branches meet at the switch: continuity to the closed form's error there.
  const double below = so3::RodriguesCoefficientE(std::nextafter(0.25, 0.0));
  const double above = so3::RodriguesCoefficientE(0.25);
  EXPECT_LE(std::abs(below - above), 1e-13 * std::abs(above));
}

TEST(Se3, AdjointConjugatesTwists) {
  std::mt19937 rng(11);
  for (int i = 0; i < 100; ++i) {
    const SE3 T = SE3::Exp(SampleTwist(rng, i));
    const Vec6 xi = 0.3 * SampleTwist(rng, i + 2);
    const SE3 lhs = SE3::Exp(T.Adjoint() * xi);
    const SE3 rhs = T * SE3::Exp(xi) * T.Inverse();
    EXPECT_LT((lhs.Matrix() - rhs.Matrix()).norm(), 1e-9);
  }
}

// Ad(Exp(ξ)) = I + ξ^⋏·𝒥(ξ) (Barfoot eq. 7.92) ties curlyhat, J and Ad together.
TEST(Se3, CurlyHatJacobianAndAdjointAreConsistent) {
  std::mt19937 rng(12);
  for (int i = 0; i < 500; ++i) {
    const Vec6 xi = SampleTwist(rng, i);
    const Mat6 lhs = SE3::Exp(xi).Adjoint();
    const Mat6 rhs = Mat6::Identity() + se3::CurlyHat(xi) * se3::LeftJacobian(xi);
    EXPECT_LT((lhs - rhs).norm(), 1e-10 * std::max(1.0, xi.squaredNorm()));
  }
  // curlyhat(ξ)·η = −curlyhat(η)·ξ (antisymmetry of the Lie bracket).
  Vec6 a, b;
  a << 1, 2, 3, 4, 5, 6;
  b << -0.3, 0.2, 0.9, -1.1, 0.4, 0.0;
  EXPECT_LT((se3::CurlyHat(a) * b + se3::CurlyHat(b) * a).norm(), 1e-14);
}

TEST(Se3, CompositionInverseAndPointAction) {
  std::mt19937 rng(13);
  const SE3 A = SE3::Exp(SampleTwist(rng, 2));
  const SE3 B = SE3::Exp(SampleTwist(rng, 3));
  const Vec3 p(1.0, -2.0, 0.5);
  EXPECT_LT(((A * B).Matrix() - A.Matrix() * B.Matrix()).norm(), 1e-12);
  EXPECT_LT(((A * A.Inverse()).Matrix() - Mat4::Identity()).norm(), 1e-12);
  EXPECT_LT(((A * p) - (A.Matrix() * p.homogeneous()).head<3>()).norm(), 1e-12);
}

TEST(Se3, PointJacobianMatchesCentralDifferences) {
  std::mt19937 rng(14);
  const double h = 1e-6;
  for (int i = 0; i < 50; ++i) {
    const SE3 T = SE3::Exp(SampleTwist(rng, i));
    const Vec3 p(2.0, -1.0, 3.0);
    Eigen::Matrix<double, 3, 6> numeric;
    for (int k = 0; k < 6; ++k) {
      const Vec6 e = Vec6::Unit(k) * h;
      numeric.col(k) = ((SE3::Exp(e) * T) * p - (SE3::Exp(-e) * T) * p) / (2.0 * h);
    }
    EXPECT_LT((numeric - se3::PointJacobian(T * p)).norm(), 1e-7);
  }
}

}  // namespace
}  // namespace ctlio
