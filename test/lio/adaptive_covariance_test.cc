// The adaptive covariance's parts (adaptive_covariance.h) on cases with a known answer: the
// lidar spread of residuals with a plane-shared error, the group-scaled covariance of a linear
// Gaussian pose, and the variance components of a group whose noise is half the configured σ.
#include "ctlio/solvers/lio/adaptive_covariance.h"

#include <gtest/gtest.h>

#include <random>

#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/pose_covariance.h"

namespace ctlio::lio {
namespace {

SE3 FarPose() { return SE3::Exp((Vec6() << 5.0, -3.0, 2.0, 0.4, -0.7, 1.1).finished()); }

// 400 planes of 5 residuals, e = c_j + ν_i, σ_c = 2 cm, σ_p = 1 cm, each plane in its own cell.
TEST(LidarSpread, SeparatesThePointNoiseFromThePlaneSharedError) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  std::vector<double> e;
  std::vector<Vec3> at;
  for (int j = 0; j < 400; ++j) {
    const double c = 0.02 * n(rng);
    for (int i = 0; i < 5; ++i) {
      e.push_back(c + 0.01 * n(rng));
      at.push_back(Vec3(2.0 * j + 0.1 * i, 0.5, 0.5));
    }
  }
  const LidarSpread s = MeasureLidarSpread(e, at, 1.0);
  EXPECT_EQ(s.groups, 400);
  EXPECT_DOUBLE_EQ(s.mean_group_size, 5.0);
  // MAD-based variances from 2000 deviations / 400 means: relative σ ≈ 5 % / 11 %; bounds 3σ.
  EXPECT_NEAR(s.point_variance, 1e-4, 0.15e-4);
  EXPECT_NEAR(s.common_variance, 4e-4, 1.3e-4);
  EXPECT_NEAR(s.effective_variance(), 1e-4 + 5 * 4e-4, 0.3 * 2.1e-3);
  // The same residuals, every one in its own cell: only their total spread is seen, 5e-4 —
  // a quarter of what the shared error makes a residual worth (the 2000 values are 400
  // independent groups: relative σ of the MAD variance ≈ 8 %; bound 3σ).
  std::vector<Vec3> apart;
  for (size_t i = 0; i < e.size(); ++i) apart.push_back(Vec3(2.0 * i, 0.5, 0.5));
  const LidarSpread t = MeasureLidarSpread(e, apart, 1.0);
  EXPECT_EQ(t.point_variance, 0.0);
  EXPECT_NEAR(t.effective_variance(), 5e-4, 1.25e-4);
  EXPECT_LT(t.effective_variance(), 0.5 * s.effective_variance());
}

// Residuals of two kinds, σ 1 cm and 4 cm (near points on thin planes, far ones or thick
// planes), each drawn with its own σ: in units of each residual's own variance the lidar's
// spread is 1 (×n_eff); measured against the 1 cm alone it reads ~3× (the mixture's MAD
// variance: the median |e| is 1.16 cm), which would make the covariance that much too
// pessimistic for every residual, the near ones on thin planes included.
TEST(LidarVarianceFactor, IsInUnitsOfEachResidualsOwnVariance) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  std::vector<double> e, sigma, nominal;
  std::vector<Vec3> at;
  for (int i = 0; i < 2000; ++i) {
    const double s = i % 2 == 0 ? 0.01 : 0.04;
    e.push_back(s * n(rng));
    sigma.push_back(s);
    nominal.push_back(0.01);
    at.push_back(Vec3(2.0 * i, 0.5, 0.5));  // each in its own cell
  }
  // The MAD variance of 2000 standard normals: relative σ ≈ 8 %; bound 3σ.
  EXPECT_NEAR(LidarVarianceFactor(e, sigma, at, 1.0), 1.0, 0.25);
  EXPECT_NEAR(LidarVarianceFactor(e, sigma, at, 10.0), 10.0, 2.5);
  EXPECT_GT(LidarVarianceFactor(e, nominal, at, 1.0), 2.5);
  // One σ for all: the spread in metres over σ², as before there were several.
  const double one = LidarVarianceFactor(e, nominal, at, 3.0);
  EXPECT_NEAR(one, 3.0 * MeasureLidarSpread(e, at, kLidarPlaneCell).effective_variance() / 1e-4,
              1e-12 * one);
  EXPECT_THROW(LidarVarianceFactor(e, std::vector<double>(3, 0.01), at, 1.0),
               std::invalid_argument);
}

// One pose under two Gaussian "groups" and a "prior": Σ = (Σ_g P_g⁻¹/s_g)⁻¹ exactly.
TEST(GroupScaledPoseCovariance, IsTheScaledInformationInverted) {
  const SE3 T = FarPose();
  SlidingWindow window;
  window.AddPoseState(0, T);
  const Mat6 P0 = (Vec6() << 1e-4, 2e-4, 3e-4, 1e-6, 2e-6, 3e-6).finished().asDiagonal();
  Mat6 P1 = Mat6::Identity() * 5e-5;
  P1(0, 3) = P1(3, 0) = 1e-6;
  const Mat6 P2 = Mat6::Identity() * 1e-3;
  const auto a = window.AddResidualBlock(PosePrior::FromCovariance(T, P0), nullptr, {0});
  const auto b = window.AddResidualBlock(PosePrior::FromCovariance(T, P1), nullptr, {0});
  const auto p = window.AddResidualBlock(PosePrior::FromCovariance(T, P2), nullptr, {0});
  // The baseline's convention: the stored pose is T_mr, tangent_from_body = Ad(T).
  const auto S =
      GroupScaledPoseCovariance(window, 0, {{{a}, 0.5}, {{b}, 4.0}}, p, 0.1, T, T.Adjoint());
  ASSERT_TRUE(S.has_value());
  const Mat6 expected = (P0.inverse() / 0.5 + P1.inverse() / 4.0 + P2.inverse() / 0.1).inverse();
  EXPECT_LT((S->scaled - expected).norm(), 1e-9 * expected.norm());
  // At scale 1 it is ceres::Covariance's.
  const std::optional<Mat6> C = PoseCovariance(&window.problem(), window.State(0), T, T.Adjoint());
  ASSERT_TRUE(C.has_value());
  EXPECT_LT((S->unscaled - *C).norm(), 1e-8 * C->norm());
  // tr(H_s⁻¹·H_g/s_g) of a group: its share of the 6 tangent directions (they sum to 6).
  const double prior_share = (S->scaled * P2.inverse() / 0.1).trace();
  EXPECT_NEAR(S->trace_share[0] + S->trace_share[1] + prior_share, 6.0, 1e-9);
}

// 300 pose measurements configured with σ but drawn with σ/2, a weak prior: the variance
// component of that group converges to 1/4 (χ² of 1794 redundant residuals: ±3.3 %), and the
// covariance reported to a quarter of the window's; the prior's factor follows (eq. 2).
TEST(AdaptiveNoiseScales, FindsTheVarianceOfAGroupDrawnWithHalfItsSigma) {
  const SE3 truth = FarPose();
  const Mat6 R = (Vec6() << 4e-4, 4e-4, 4e-4, 1e-4, 1e-4, 1e-4).finished().asDiagonal();
  const Mat6 L = Mat6(R.llt().matrixL()) * 0.5;  // the drawn noise
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  SlidingWindow window;
  window.AddPoseState(0, truth);
  std::vector<ceres::ResidualBlockId> group;
  for (int k = 0; k < 300; ++k) {
    Vec6 z;
    for (int i = 0; i < 6; ++i) z[i] = n(rng);
    group.push_back(window.AddResidualBlock(PosePrior::FromCovariance(SE3::Exp(L * z) * truth, R),
                                            nullptr, {0}));
  }
  const auto prior =
      window.AddResidualBlock(PosePrior::FromCovariance(truth, R * 1e4), nullptr, {0});
  ASSERT_TRUE(window.Solve().IsSolutionUsable());
  const SE3 T = window.Pose(0);
  const std::optional<Mat6> C = PoseCovariance(&window.problem(), window.State(0), T, T.Adjoint());
  ASSERT_TRUE(C.has_value());

  AdaptiveNoiseScales scales;
  std::optional<Mat6> S;
  for (int scan = 0; scan < 40; ++scan) {
    S = scales.Compute(&window, 0, 1.0, {}, group, {}, prior, T, T.Adjoint());
    ASSERT_TRUE(S.has_value());
  }
  EXPECT_NEAR(scales.accel(), 0.25, 0.25 * 0.1);
  EXPECT_DOUBLE_EQ(scales.gyro(), 1.0);  // no residuals: left as it was
  EXPECT_NEAR(scales.prior(), scales.accel(), 0.01);
  EXPECT_LT((*S - scales.accel() * *C).norm(), 0.01 * (scales.accel() * *C).norm());
}

}  // namespace
}  // namespace ctlio::lio
