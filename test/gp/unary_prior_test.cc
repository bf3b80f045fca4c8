// Unary priors (factors/priors: pose, velocity, acceleration, full state): residual values
// and Jacobians against GradientChecker at large and small rotations.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/factors/priors/state_prior.h"

namespace ctlio {
namespace {

using testing::PoseParameters;
using testing::RandomPose;
using testing::RandomVec6;
const PoseManifold kPoseManifold;

Mat6 RandomSpd6(std::mt19937& rng) {
  Mat6 A;
  for (int i = 0; i < 6; ++i) A.col(i) = RandomVec6(rng, 1.0);
  return A * A.transpose() + 0.1 * Mat6::Identity();
}

TEST(PosePriorTest, ResidualAndJacobians) {
  std::mt19937 rng(1);
  for (double angle : {3.1, 1.0, 1e-7}) {
    const SE3 mean = RandomPose(rng, 3.0, 5.0);
    const SE3 T = RandomPose(rng, angle, 1.0) * mean;
    const Mat6 cov = RandomSpd6(rng);
    std::unique_ptr<PosePrior> prior(PosePrior::FromCovariance(mean, cov));
    const std::vector<double> x = PoseParameters(T);
    EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(*prior, {&kPoseManifold}, {x.data()}, 1e-8));
    Vec6 r;
    const double* p[1] = {x.data()};
    prior->Evaluate(p, r.data(), nullptr);
    // rᵀr = eᵀΣ⁻¹e.
    const Vec6 e = (T * mean.Inverse()).Log();
    EXPECT_NEAR(r.squaredNorm(), e.dot(cov.inverse() * e), 1e-9 * (1 + r.squaredNorm()));
  }
}

TEST(EuclideanPriorTest, VelocityAndAccelerationPriors) {
  std::mt19937 rng(2);
  const Vec6 mean = RandomVec6(rng, 1.0), x = RandomVec6(rng, 2.0);
  const Mat6 cov = RandomSpd6(rng);
  std::unique_ptr<VelocityPrior> v(VelocityPrior::FromCovariance(mean, cov));
  std::unique_ptr<AccelerationPrior> a(AccelerationPrior::FromCovariance(mean, cov));
  EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(*v, {nullptr}, {x.data()}, 1e-9));
  Vec6 r;
  const double* p[1] = {x.data()};
  a->Evaluate(p, r.data(), nullptr);
  EXPECT_NEAR(r.squaredNorm(), (x - mean).dot(cov.inverse() * (x - mean)), 1e-9);
}

TEST(StatePriorTest, ResidualAndJacobians) {
  std::mt19937 rng(3);
  for (double angle : {3.0, 1e-7}) {
    const SE3 mean = RandomPose(rng, 3.0, 5.0);
    const Vec6 v0 = RandomVec6(rng, 1.0), a0 = RandomVec6(rng, 1.0);
    Eigen::Matrix<double, 18, 18> A;
    for (int i = 0; i < 18; ++i)
      for (int j = 0; j < 3; ++j) A.block<6, 1>(6 * j, i) = RandomVec6(rng, 1.0);
    const Eigen::Matrix<double, 18, 18> cov =
        A * A.transpose() + 0.1 * Eigen::Matrix<double, 18, 18>::Identity();
    std::unique_ptr<StatePrior> prior(StatePrior::FromCovariance(mean, v0, a0, cov));
    const std::vector<double> x = PoseParameters(RandomPose(rng, angle, 1.0) * mean);
    const Vec6 v = RandomVec6(rng, 1.0), a = RandomVec6(rng, 1.0);
    EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(*prior, {&kPoseManifold, nullptr, nullptr},
                                                      {x.data(), v.data(), a.data()}, 1e-8));
  }
}

TEST(UnaryPriorTest, RejectsNonPositiveDefiniteCovariance) {
  Mat6 cov = Mat6::Identity();
  cov(2, 2) = -1.0;
  EXPECT_THROW(PosePrior::FromCovariance(SE3(), cov), std::invalid_argument);
  EXPECT_THROW(VelocityPrior::FromCovariance(Vec6::Zero(), cov), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio
