// Motion models of SPEC §2: known values, Q against long-double numerical integration over the
// α × Δt grid (α from 0 to 1e4, Δt from 1e-5 to 10 s), positive definiteness, whitening,
// series/closed-form continuity.
#include "ctlio/factors/gp/motion_model.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace ctlio::gp {
namespace {

using LD = long double;

::testing::AssertionResult RelNear(double actual, double expected, double tol) {
  const double err = std::abs(actual - expected) / std::abs(expected);
  if (err <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "actual " << actual << " expected " << expected
                                       << " relative error " << err << " > " << tol;
}

TEST(SingerModelTest, KnownValuesAlpha1) {
  const Eigen::Matrix3d P = SingerTransition(1.0, 0.1);
  EXPECT_TRUE(RelNear(P(0, 2), 4.8374180360e-3, 1e-9));
  EXPECT_TRUE(RelNear(P(1, 2), 9.5162581964e-2, 1e-9));
  EXPECT_TRUE(RelNear(P(2, 2), 9.0483741804e-1, 1e-9));
  EXPECT_EQ(P(0, 1), 0.1);
  const Eigen::Matrix3d Q = SingerCovariance(1.0, 1.0, 0.1);
  EXPECT_TRUE(RelNear(Q(0, 0), 4.7318715049e-7, 1e-9));
  EXPECT_TRUE(RelNear(Q(0, 1), 1.1700306627e-5, 1e-9));
  EXPECT_TRUE(RelNear(Q(0, 2), 1.5088165741e-4, 1e-9));
  EXPECT_TRUE(RelNear(Q(1, 1), 3.0945953293e-4, 1e-9));
  EXPECT_TRUE(RelNear(Q(1, 2), 4.5279585030e-3, 1e-9));
  EXPECT_TRUE(RelNear(Q(2, 2), 9.0634623461e-2, 1e-9));
  EXPECT_EQ(Q, Q.transpose());
}

TEST(SingerModelTest, KnownValuesAlpha100) {
  const Eigen::Matrix3d Q = SingerCovariance(100.0, 500.0, 0.1);
  EXPECT_TRUE(RelNear(Q(0, 0), 1.2191621267e-5, 1e-9));
  EXPECT_TRUE(RelNear(Q(1, 1), 4.2500453994e-3, 1e-9));
  EXPECT_TRUE(RelNear(Q(2, 2), 2.4999999948, 1e-9));
}

TEST(SingerModelTest, WnojInformationKnownValues) {
  const Eigen::Matrix3d I = SingerInformation(0.0, 1.0, 0.1);
  Eigen::Matrix3d expected;
  expected << 7.2e7, -3.6e6, 6.0e4, -3.6e6, 1.92e5, -3.6e3, 6.0e4, -3.6e3, 90.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(RelNear(I(i, j), expected(i, j), 1e-9)) << i << j;
}

TEST(SingerModelTest, AlphaZeroIsExactlyWnoj) {
  const double dt = 0.37, qc = 2.5;
  Eigen::Matrix3d P, Q;
  P << 1, dt, dt * dt / 2, 0, 1, dt, 0, 0, 1;
  Q << std::pow(dt, 5) / 20, std::pow(dt, 4) / 8, std::pow(dt, 3) / 6,  //
      std::pow(dt, 4) / 8, std::pow(dt, 3) / 3, dt * dt / 2,            //
      std::pow(dt, 3) / 6, dt * dt / 2, dt;
  Q *= qc;
  EXPECT_TRUE(SingerTransition(0.0, dt).isApprox(P, 1e-15));
  EXPECT_TRUE(SingerCovariance(0.0, qc, dt).isApprox(Q, 1e-15));
  // And the limit α → 0 is continuous: relative differences O(x).
  const Eigen::Matrix3d Qs = SingerCovariance(1e-12, qc, dt);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(RelNear(Qs(i, j), Q(i, j), 1e-11));
}

TEST(SingerModelTest, SeriesAndClosedFormAgreeAtTheSwitch) {
  // Both branches evaluated at the switch and at the neighbouring doubles: continuity of
  // every function to a few ulps (bound 5e-15 relative).
  const double xs[] = {std::nextafter(kSingerSeriesSwitch, 0.0), kSingerSeriesSwitch,
                       std::nextafter(kSingerSeriesSwitch, 10.0), 0.9 * kSingerSeriesSwitch,
                       1.1 * kSingerSeriesSwitch};
  for (double x : xs) {
    const SingerShape a = SingerShapeSeries(x), b = SingerShapeClosedForm(x);
    const double va[] = {a.e, a.g1, a.g2, a.q11, a.q12, a.q13, a.q22, a.q23, a.q33};
    const double vb[] = {b.e, b.g1, b.g2, b.q11, b.q12, b.q13, b.q22, b.q23, b.q33};
    for (int k = 0; k < 9; ++k)
      EXPECT_TRUE(RelNear(va[k], vb[k], 5e-15)) << "x " << x << " k " << k;
  }
  // The dispatcher itself across the switch.
  const SingerShape lo = EvaluateSingerShape(std::nextafter(kSingerSeriesSwitch, 0.0));
  const SingerShape hi = EvaluateSingerShape(kSingerSeriesSwitch);
  EXPECT_TRUE(RelNear(lo.q11, hi.q11, 5e-15));
  EXPECT_TRUE(RelNear(lo.q22, hi.q22, 5e-15));
  EXPECT_TRUE(RelNear(lo.q33, hi.q33, 5e-15));
}

// ---- Reference: Q = Qc ∫₀^Δt f fᵀ ds, f(s) = Φ(s)L = [s²g2(αs), s·g1(αs), e^{−αs}], in long
// double with composite Gauss–Legendre on geometrically graded panels. g1, g2 by their own
// term-recursion series (y < 1) or expm1l closed forms: an implementation independent of the
// tables under test.
LD RefG1(LD y) {
  if (y < 1) {
    LD term = 1, sum = 0;
    for (int n = 1; n < 60; ++n) {
      term /= n;  // (−y)^{n−1}/n!
      sum += term;
      term *= -y;
    }
    return sum;
  }
  return -std::expm1l(-y) / y;
}
LD RefG2(LD y) {
  if (y < 1) {
    LD term = 0.5L, sum = 0;  // (−y)^n/(n+2)!
    for (int n = 0; n < 60; ++n) {
      sum += term;
      term *= -y / (n + 3);
    }
    return sum;
  }
  return (y + std::expm1l(-y)) / (y * y);
}

struct GaussLegendre {
  std::vector<LD> x, w;  // on [0, 1]
  explicit GaussLegendre(int n) {
    const LD pi = 3.141592653589793238462643383279502884L;
    for (int i = 1; i <= n; ++i) {
      LD z = std::cos(pi * (i - 0.25L) / (n + 0.5L)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        LD p0 = 1, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const LD p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1);
        const LD dz = p1 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-21L) break;
      }
      x.push_back((1 - z) / 2);
      w.push_back(1 / ((1 - z * z) * dp * dp));
    }
  }
};

Eigen::Matrix<LD, 3, 3> ReferenceQ(LD alpha, LD qc, LD dt) {
  static const GaussLegendre gl(30);
  std::vector<LD> edges{0};
  if (alpha * dt <= 1) {
    for (int k = 1; k <= 4; ++k) edges.push_back(dt * k / 4);
  } else {
    LD h = 0.125L / alpha;
    while (h < dt) {
      edges.push_back(h);
      h *= 2;
    }
    edges.push_back(dt);
  }
  Eigen::Matrix<LD, 3, 3> Q = Eigen::Matrix<LD, 3, 3>::Zero();
  for (std::size_t p = 0; p + 1 < edges.size(); ++p) {
    const LD a = edges[p], len = edges[p + 1] - a;
    for (std::size_t i = 0; i < gl.x.size(); ++i) {
      const LD s = a + len * gl.x[i];
      const LD y = alpha * s;
      const Eigen::Matrix<LD, 3, 1> f(s * s * RefG2(y), s * RefG1(y), std::exp(-y));
      Q += (len * gl.w[i]) * f * f.transpose();
    }
  }
  return qc * Q;
}

TEST(SingerModelTest, CovarianceMatchesNumericalIntegrationOnGrid) {
  const double alphas[] = {0, 1e-12, 1e-6, 1e-3, 0.1, 1, 10, 100, 1e4};
  const double dts[] = {1e-5, 1e-3, 0.01, 0.1, 1, 10};
  const double qc = 3.0;
  double worst = 0;
  for (double alpha : alphas) {
    for (double dt : dts) {
      const Eigen::Matrix3d Q = SingerCovariance(alpha, qc, dt);
      const Eigen::Matrix<LD, 3, 3> R = ReferenceQ(alpha, qc, dt);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          const double ref = static_cast<double>(R(i, j));
          const double err = std::abs(Q(i, j) - ref) / ref;
          worst = std::max(worst, err);
          EXPECT_LE(err, 1e-9) << "alpha " << alpha << " dt " << dt << " entry " << i << j << " Q "
                               << Q(i, j) << " ref " << ref;
        }
      }
      EXPECT_EQ(Q, Q.transpose());
      // Positive definite: Cholesky succeeds and the scaled matrix D⁻¹QD⁻¹ has a positive
      // smallest eigenvalue.
      Eigen::LLT<Eigen::Matrix3d> llt(Q);
      EXPECT_EQ(llt.info(), Eigen::Success) << alpha << " " << dt;
      const Eigen::Vector3d d(std::pow(dt, -2.5), std::pow(dt, -1.5), std::pow(dt, -0.5));
      const Eigen::Matrix3d S = d.asDiagonal() * Q * d.asDiagonal();
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvalues()[0], 0.0);
      // Whitening: W Q Wᵀ = I and WᵀW = Q⁻¹.
      const Eigen::Matrix3d W = SingerSqrtInformation(alpha, qc, dt);
      EXPECT_TRUE((W * Q * W.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-9))
          << alpha << " " << dt << "\n"
          << W * Q * W.transpose();
      EXPECT_EQ(W(0, 1), 0.0);
      EXPECT_EQ(W(0, 2), 0.0);
      EXPECT_EQ(W(1, 2), 0.0);
    }
  }
  // Full precision in fact (measured 3.6e-16): a 1e-9 requirement would be far from binding.
  EXPECT_LE(worst, 1e-13);
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::cout << "worst relative error of Q over the grid: " << worst << "\n";
}

TEST(SingerModelTest, TransitionMatchesMatrixExponential) {
  // Φ = exp(AΔt), A = [[0,1,0],[0,0,1],[0,0,−α]], by a long-double Taylor series of exp with
  // scaling and squaring.
  for (double alpha : {0.0, 1e-8, 0.3, 5.0, 80.0}) {
    for (double dt : {1e-4, 0.05, 0.7}) {
      Eigen::Matrix<LD, 3, 3> A = Eigen::Matrix<LD, 3, 3>::Zero();
      A(0, 1) = 1;
      A(1, 2) = 1;
      A(2, 2) = -alpha;
      A *= dt / 1024.0L;
      Eigen::Matrix<LD, 3, 3> E = Eigen::Matrix<LD, 3, 3>::Identity(), term = E;
      for (int n = 1; n < 30; ++n) {
        term = term * A / n;
        E += term;
      }
      for (int k = 0; k < 10; ++k) E = E * E;
      const Eigen::Matrix3d P = SingerTransition(alpha, dt);
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
          EXPECT_TRUE(RelNear(P(i, j), static_cast<double>(E(i, j)), 1e-12)) << alpha << " " << dt;
    }
  }
}

TEST(WnoaModelTest, ValuesAndWhitening) {
  const double qc = 2.0, dt = 0.1;
  const Eigen::Matrix2d Q = WnoaCovariance(qc, dt);
  EXPECT_TRUE(RelNear(Q(0, 0), qc * 1e-3 / 3, 1e-15));
  EXPECT_TRUE(RelNear(Q(0, 1), qc * 1e-2 / 2, 1e-15));
  EXPECT_TRUE(RelNear(Q(1, 1), qc * 0.1, 1e-15));
  EXPECT_TRUE((WnoaInformation(qc, dt) * Q).isApprox(Eigen::Matrix2d::Identity(), 1e-12));
  const Eigen::Matrix2d W = WnoaSqrtInformation(qc, dt);
  EXPECT_TRUE((W * Q * W.transpose()).isApprox(Eigen::Matrix2d::Identity(), 1e-12));
  EXPECT_EQ(WnoaTransition(dt)(0, 1), dt);
}

TEST(SingerModelTest, StackedModelMatchesPerAxis) {
  Eigen::Matrix<double, 3, 1> qc(1.0, 2.0, 3.0), alpha(0.0, 0.0, 50.0);
  const SingerModel<3> model(qc, alpha);
  const double dt = 0.08;
  const auto P = model.Transition(dt);
  const auto Q = model.Covariance(dt);
  const auto W = model.SqrtInformation(dt);
  for (int a = 0; a < 3; ++a) {
    const Eigen::Matrix3d Pa = SingerTransition(alpha[a], dt);
    const Eigen::Matrix3d Qa = SingerCovariance(alpha[a], qc[a], dt);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        EXPECT_DOUBLE_EQ(P(3 * i + a, 3 * j + a), Pa(i, j));
        EXPECT_DOUBLE_EQ(Q(3 * i + a, 3 * j + a), Qa(i, j));
      }
  }
  EXPECT_TRUE((W * Q * W.transpose()).isApprox(Eigen::Matrix<double, 9, 9>::Identity(), 1e-9));
  EXPECT_TRUE((model.Information(dt) * Q).isApprox(Eigen::Matrix<double, 9, 9>::Identity(), 1e-8));
  // Block-structured product equals the dense one.
  const auto Pb = model.TransitionBlocks(dt);
  const Eigen::Matrix<double, 9, 1> x = Eigen::Matrix<double, 9, 1>::LinSpaced(-1.0, 2.0);
  EXPECT_TRUE((Pb * x).isApprox(P * x, 1e-15));
  EXPECT_TRUE((Pb * Pb).ToDense().isApprox(P * P, 1e-15));
}

TEST(SingerModelTest, RejectsBadArguments) {
  EXPECT_THROW(SingerCovariance(-1.0, 1.0, 0.1), std::runtime_error);
  EXPECT_THROW(SingerCovariance(1.0, 0.0, 0.1), std::runtime_error);
  EXPECT_THROW(SingerTransition(1.0, 0.0), std::runtime_error);
  EXPECT_THROW(SingerTransition(1.0, std::numeric_limits<double>::quiet_NaN()), std::runtime_error);
  EXPECT_THROW(WnoaCovariance(1.0, -0.1), std::runtime_error);
  try {
    SingerCovariance(1.0, 1.0, -1.0);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("motion_model"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SingerModel<2>(Eigen::Vector2d(1, 1), Eigen::Vector2d(1, -2)), std::runtime_error);
}

}  // namespace
}  // namespace ctlio::gp
