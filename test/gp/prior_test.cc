// SE(3) SingerPrior and the vector-space prior (SPEC §2): Jacobians against GradientChecker,
// zero error on the prior mean, and samples drawn from the prior having the predicted
// covariance (fixed seeds, 5% bounds).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/gp/vector_prior.h"

namespace ctlio::gp {
namespace {

using ctlio::testing::PoseParameters;
using ctlio::testing::RandomPose;
using ctlio::testing::RandomVec6;
const PoseManifold kPoseManifold;

struct Blocks {
  std::vector<double> p0, v0, a0, p1, v1, a1;
  std::vector<const double*> ptrs() const {
    return {p0.data(), v0.data(), a0.data(), p1.data(), v1.data(), a1.data()};
  }
};

Blocks ToBlocks(const KnotState& k, const KnotState& k1) {
  Blocks b;
  b.p0 = PoseParameters(k.pose);
  b.p1 = PoseParameters(k1.pose);
  b.v0.assign(k.velocity.data(), k.velocity.data() + 6);
  b.a0.assign(k.acceleration.data(), k.acceleration.data() + 6);
  b.v1.assign(k1.velocity.data(), k1.velocity.data() + 6);
  b.a1.assign(k1.acceleration.data(), k1.acceleration.data() + 6);
  return b;
}

TEST(SingerPriorTest, JacobiansMatchNumeric) {
  struct Case {
    const char* name;
    double rel_angle, vel, acc;
    Vec6 alpha;
    double dt;
  };
  Vec6 a_lio, a_switch, a_mixed;
  a_lio << 0, 0, 0, 100, 100, 100;
  a_switch << 12.5, 12.4999999, 12.5000001, 12.5, 1e-9, 0;  // α·Δt at the switch x = 1.25
  a_mixed << 0, 1e-6, 0.5, 7.0, 40.0, 1e3;
  const Case cases[] = {{"large_rotation_wnoj", 3.0, 4.0, 8.0, Vec6::Zero(), 0.1},
                        {"large_rotation_singer", 3.1, 4.0, 8.0, a_lio, 0.1},
                        {"small_rotation", 1e-7, 1e-6, 1e-6, a_lio, 0.1},
                        {"near_series_switch", 0.8, 1.0, 1.0, a_switch, 0.1},
                        {"mixed_alpha", 1.5, 1.0, 1.0, a_mixed, 0.7}};
  std::mt19937 rng(21);
  Vec6 qc;
  qc << 5000, 5000, 5000, 500, 500, 500;
  for (const Case& c : cases) {
    const SingerPrior prior(SingerModel<6>(qc, c.alpha), c.dt);
    for (int trial = 0; trial < 3; ++trial) {
      KnotState k, k1;
      k.pose = RandomPose(rng, 3.1, 10.0);
      k1.pose = RandomPose(rng, c.rel_angle, 1.0) * k.pose;
      k.velocity = RandomVec6(rng, c.vel);
      k1.velocity = RandomVec6(rng, c.vel);
      k.acceleration = RandomVec6(rng, c.acc);
      k1.acceleration = RandomVec6(rng, c.acc);
      const Blocks b = ToBlocks(k, k1);
      // Residuals are whitened (|W| up to ~1e4 here), so the numeric derivative's noise floor at
      // zero entries reaches 1e-10: absolute = relative = 1e-8 (still tighter than the former
      // block-scaled bound 1e-8·max(1, max|J_block|), see test/common/gradient_check.h).
      EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(
          prior, {&kPoseManifold, nullptr, nullptr, &kPoseManifold, nullptr, nullptr}, b.ptrs(),
          1e-8, 1e-8))
          << c.name;
    }
  }
}

TEST(SingerPriorTest, JacobianUsesTheSingerTransition) {
  // ∂r/∂ϖ̇_k = −W·Φ(:, a-columns) with the Singer Φ (the reference code uses WNOJ's there).
  Vec6 qc = Vec6::Constant(10.0), alpha = Vec6::Constant(30.0);
  const double dt = 0.1;
  const SingerPrior prior(SingerModel<6>(qc, alpha), dt);
  const Blocks b = ToBlocks(KnotState{}, KnotState{});
  double res[18], j[6][18 * 7];
  double* jac[6] = {j[0], j[1], j[2], j[3], j[4], j[5]};
  const auto p = b.ptrs();
  ASSERT_TRUE(prior.Evaluate(p.data(), res, jac));
  const Eigen::Matrix3d W = SingerSqrtInformation(30.0, 10.0, dt);
  const Eigen::Matrix3d expected = -W * SingerTransition(30.0, dt);
  Eigen::Map<Eigen::Matrix<double, 18, 6, Eigen::RowMajor>> Ja(j[2]);
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(Ja(6 * r, 0), expected(r, 2), 1e-9 * std::abs(W(2, 2)));
}

TEST(SingerPriorTest, ZeroOnThePriorMean) {
  std::mt19937 rng(4);
  Vec6 qc = Vec6::Constant(1.0), alpha;
  alpha << 0, 0, 0, 100, 100, 100;
  const SingerModel<6> model(qc, alpha);
  const double dt = 0.1;
  const SingerPrior prior(model, dt);
  KnotState k;
  k.pose = RandomPose(rng, 3.0, 5.0);
  k.velocity = RandomVec6(rng, 2.0);
  k.acceleration = RandomVec6(rng, 2.0);
  KnotState k1;
  GpExtrapolator(model, 0.0, dt).State(k, &k1, nullptr);
  EXPECT_LE(prior.Error(k, k1).norm(), 1e-12);
  // A perturbation gives a non-zero error.
  k1.velocity[3] += 0.1;
  EXPECT_GT(prior.Error(k, k1).norm(), 0.05);
}

// Euler–Maruyama simulation of ȧ = −αa + w (fine steps), independent of the closed forms.
Eigen::Vector3d SimulateSinger(std::mt19937& rng, double alpha, double qc, double dt, int steps) {
  std::normal_distribution<double> n(0.0, 1.0);
  const double h = dt / steps, s = std::sqrt(qc * h);
  double p = 0, v = 0, a = 0;
  for (int i = 0; i < steps; ++i) {
    const double w = s * n(rng);
    p += v * h + 0.5 * a * h * h;
    v += a * h + 0.5 * w * h;  // midpoint in the noise keeps the O(h) bias small
    a += -alpha * a * h + w;
  }
  return Eigen::Vector3d(p, v, a);
}

TEST(VectorGpPriorTest, SimulatedSamplesHaveThePredictedCovariance) {
  // x(Δt) from x(0) = 0 is N(0, Q(Δt)); the whitened prior residual must then be N(0, I).
  std::mt19937 rng(1234);
  const int n = 20000, steps = 100;
  for (double alpha : {0.0, 10.0}) {
    const double qc = 1.0, dt = 0.1;
    std::unique_ptr<VectorGpPrior<3>> prior(MakeSingerPrior1D(alpha, qc, dt));
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero(), R = Eigen::Matrix3d::Zero();
    const double x0[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d x = SimulateSinger(rng, alpha, qc, dt, steps);
      C += x * x.transpose();
      const double* p[2] = {x0, x.data()};
      Eigen::Vector3d r;
      prior->Evaluate(p, r.data(), nullptr);
      R += r * r.transpose();
    }
    C /= n;
    R /= n;
    const Eigen::Matrix3d Q = SingerCovariance(alpha, qc, dt);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(C(i, j), Q(i, j), 0.05 * std::abs(Q(i, j))) << alpha << " " << i << j;
    EXPECT_LE((R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 0.05) << R;
    std::cout << "alpha " << alpha << ": max relative covariance error "
              << ((C - Q).cwiseQuotient(Q)).cwiseAbs().maxCoeff() << ", whitened max |R - I| "
              << (R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() << "\n";
  }
}

TEST(SingerPriorTest, PriorSamplesWhitenToIdentity) {
  // γ_{k+1} ~ N(Φγ_k, Q) drawn per axis, mapped to a knot (T = Exp(ξ)T_k, ϖ = Jξ̇, ϖ̇ =
  // J(ξ̈ + ½ξ̇^⋏ϖ)): the SE(3) prior's whitened residual has identity covariance.
  std::mt19937 rng(99);
  std::normal_distribution<double> nd(0.0, 1.0);
  Vec6 qc, alpha;
  qc << 2, 2, 2, 0.5, 0.5, 0.5;
  alpha << 0, 0, 0, 20, 20, 20;
  const SingerModel<6> model(qc, alpha);
  const double dt = 0.1;
  const SingerPrior prior(model, dt);
  const auto L =
      Eigen::Matrix<double, 18, 18>(model.Covariance(dt)).llt().matrixL().toDenseMatrix();
  KnotState k;
  k.pose = RandomPose(rng, 1.0, 2.0);
  k.velocity = RandomVec6(rng, 1.0);
  k.acceleration = RandomVec6(rng, 1.0);
  Eigen::Matrix<double, 18, 1> gk;
  gk << Vec6::Zero(), k.velocity, k.acceleration;
  const Eigen::Matrix<double, 18, 1> mean = model.Transition(dt) * gk;
  const int n = 20000;
  Eigen::Matrix<double, 18, 18> S = Eigen::Matrix<double, 18, 18>::Zero();
  const Blocks b0 = ToBlocks(k, k);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 18, 1> z;
    for (int j = 0; j < 18; ++j) z[j] = nd(rng);
    const Eigen::Matrix<double, 18, 1> g = mean + L * z;
    const Vec6 xi = g.head<6>(), xd = g.segment<6>(6), xdd = g.tail<6>();
    const Mat6 J = se3::LeftJacobian(xi);
    KnotState k1;
    k1.pose = SE3::Exp(xi) * k.pose;
    k1.velocity = J * xd;
    k1.acceleration = J * (xdd + 0.5 * se3::CurlyHat(xd) * k1.velocity);
    Blocks b = b0;
    b.p1 = PoseParameters(k1.pose);
    b.v1.assign(k1.velocity.data(), k1.velocity.data() + 6);
    b.a1.assign(k1.acceleration.data(), k1.acceleration.data() + 6);
    Eigen::Matrix<double, 18, 1> r;
    const auto p = b.ptrs();
    prior.Evaluate(p.data(), r.data(), nullptr);
    S += r * r.transpose();
  }
  S /= n;
  const double err = (S - Eigen::Matrix<double, 18, 18>::Identity()).cwiseAbs().maxCoeff();
  EXPECT_LE(err, 0.05);
  std::cout << "SE(3) prior samples: max |S - I| = " << err << "\n";
}

TEST(VectorGpPriorTest, JacobiansAndStackedModel) {
  std::mt19937 rng(8);
  Eigen::Vector2d qc(1.0, 3.0), alpha(0.0, 5.0);
  std::unique_ptr<VectorGpPrior<6>> prior(MakeSingerVectorPrior(SingerModel<2>(qc, alpha), 0.2));
  std::uniform_real_distribution<double> u(-1, 1);
  double x0[6], x1[6];
  for (int i = 0; i < 6; ++i) {
    x0[i] = u(rng);
    x1[i] = u(rng);
  }
  EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(*prior, {nullptr, nullptr}, {x0, x1}, 1e-9));
  std::unique_ptr<VectorGpPrior<2>> wnoa(MakeWnoaPrior1D(2.0, 0.1));
  EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(*wnoa, {nullptr, nullptr}, {x0, x1}, 1e-9));
  // Residual = W(x1 − Φx0).
  double r[2];
  const double* p[2] = {x0, x1};
  wnoa->Evaluate(p, r, nullptr);
  const Eigen::Vector2d expected =
      WnoaSqrtInformation(2.0, 0.1) *
      (Eigen::Vector2d(x1[0], x1[1]) - WnoaTransition(0.1) * Eigen::Vector2d(x0[0], x0[1]));
  EXPECT_NEAR(r[0], expected[0], 1e-12 * expected.norm());
  EXPECT_NEAR(r[1], expected[1], 1e-12 * expected.norm());
}

}  // namespace
}  // namespace ctlio::gp
