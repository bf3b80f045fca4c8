#include "ctlio/factors/imu/bias_factors.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "common/gradient_check.h"

namespace ctlio::imu {
namespace {

TEST(BiasRandomWalk, CovarianceScalesWithDt) {
  const double qa = 9e-6, qg = 3.76e-10;
  Vec6 b0 = Vec6::Zero(), b1;
  b1 << 1e-3, 2e-3, 3e-3, 1e-5, 2e-5, 3e-5;
  Vec6 r_short, r_long;
  const double* params[] = {b0.data(), b1.data()};
  BiasRandomWalk(qa, qg, 0.1).Evaluate(params, r_short.data(), nullptr);
  BiasRandomWalk(qa, qg, 0.4).Evaluate(params, r_long.data(), nullptr);
  // Σ = Q_c Δt: four times the interval halves the whitened residual.
  EXPECT_LT((r_short - 2.0 * r_long).norm(), 1e-12 * r_short.norm());
  EXPECT_NEAR(r_short[0], 1e-3 / std::sqrt(qa * 0.1), 1e-9);
  EXPECT_NEAR(r_short[5], 3e-5 / std::sqrt(qg * 0.1), 1e-9);
}

// Scaling by Δt makes the model independent of the knot rate: a linear bias
// drift over 1 s (the most likely path between its two ends) costs the same
// whether the chain has 2 or 10 knots. A fixed per-knot covariance would make
// the 10-knot chain 9 times cheaper; here the costs agree to round-off.
TEST(BiasRandomWalk, ChainCostIndependentOfKnotRate) {
  const double qa = 9e-6, qg = 3.76e-10;
  Vec6 start = Vec6::Zero(), end;
  end << 1e-3, -2e-3, 3e-3, 1e-5, -2e-5, 3e-5;
  double costs[2];
  int idx = 0;
  for (const int knots : {2, 10}) {
    const double dt = 1.0 / (knots - 1);
    double cost = 0.0;
    for (int k = 0; k + 1 < knots; ++k) {
      Vec6 a = start + (end - start) * (k * dt), b = start + (end - start) * ((k + 1) * dt);
      Vec6 r;
      const double* params[] = {a.data(), b.data()};
      BiasRandomWalk(qa, qg, dt).Evaluate(params, r.data(), nullptr);
      cost += r.squaredNorm();
    }
    costs[idx++] = cost;
  }
  EXPECT_NEAR(costs[0], costs[1], 1e-9 * costs[0]);
}

TEST(BiasRandomWalk, JacobiansAndBadInput) {
  std::mt19937 rng(2);
  Vec6 a = testing::RandomVec6(rng, 0.1), b = testing::RandomVec6(rng, 0.1);
  const BiasRandomWalk cost(1e-4, 1e-6, 0.05);
  EXPECT_TRUE(testing::JacobiansMatchNumeric(cost, {nullptr, nullptr}, {a.data(), b.data()}));
  EXPECT_THROW(BiasRandomWalk(1e-4, 1e-6, 0.0), std::invalid_argument);
  EXPECT_THROW(BiasRandomWalk(-1.0, 1e-6, 0.1), std::invalid_argument);
}

TEST(BiasPrior, WhitensAndChecksCovariance) {
  std::mt19937 rng(4);
  Vec6 mean = testing::RandomVec6(rng, 0.1), b = testing::RandomVec6(rng, 0.1);
  Mat6 A = Mat6::Random();
  const Mat6 cov = A * A.transpose() + 0.1 * Mat6::Identity();
  const BiasPrior prior(mean, cov);
  Vec6 r;
  const double* params[] = {b.data()};
  prior.Evaluate(params, r.data(), nullptr);
  EXPECT_NEAR(r.squaredNorm(), (b - mean).dot(cov.inverse() * (b - mean)), 1e-9);
  EXPECT_TRUE(testing::JacobiansMatchNumeric(prior, {nullptr}, {b.data()}));
  EXPECT_THROW(BiasPrior(mean, -Mat6::Identity()), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::imu
