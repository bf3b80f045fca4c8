// The pose covariance's convention (pose_covariance.h) on the linear-Gaussian case where the
// answer is exact: one pose under a Gaussian prior in its own state convention. The reported Σ
// must be the prior mapped to ε in T_mr(true) = Exp(ε)·T_mr ([ρ; φ]), and the error the NEES
// evaluates (run_odometry.cc PoseNees: ε = Log(T_mr(true)·T_mr⁻¹)) must have that covariance.
#include "ctlio/solvers/lio/pose_covariance.h"

#include <gtest/gtest.h>

#include <random>

#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::lio {
namespace {

// A pose far from the origin and rotated, so that frame and perturbation-side mistakes show.
SE3 FarPose() { return SE3::Exp((Vec6() << 5.0, -3.0, 2.0, 0.4, -0.7, 1.1).finished()); }

// A full-rank covariance whose translation part (cm) and rotation part (mrad) differ in scale.
Mat6 PriorCovariance() {
  std::mt19937 rng(7);
  std::normal_distribution<double> n;
  Mat6 L;
  for (int i = 0; i < 36; ++i) L(i) = n(rng);
  Mat6 S = L * L.transpose() + Mat6::Identity();
  const Vec6 scale = (Vec6() << 1e-2, 1e-2, 1e-2, 1e-3, 1e-3, 1e-3).finished();
  return scale.asDiagonal() * S * scale.asDiagonal();
}

// The covariance reported for a window holding only `stored` under a prior of covariance Σ
// (left perturbation of the stored pose, PosePrior).
Mat6 Reported(const SE3& stored, const Mat6& prior, const SE3& T_mr, const Mat6& tangent) {
  double x[7];
  PoseManifold::Store(stored, x);
  ceres::Problem problem;
  problem.AddParameterBlock(x, 7, new PoseManifold);
  problem.AddResidualBlock(PosePrior::FromCovariance(stored, prior), nullptr, x);
  const std::optional<Mat6> S = PoseCovariance(&problem, x, T_mr, tangent);
  EXPECT_TRUE(S.has_value());
  return S.value_or(Mat6::Zero());
}

// Mean NEES of ε = Log(T_mr(true)·T_mr⁻¹) over truths drawn from the state's own posterior:
// T_state(true) = Exp(δ)·T_state, δ ~ N(0, Σ_state).
double MonteCarloNees(const SE3& stored, const Mat6& prior, bool stored_is_T_rm, const Mat6& S) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n;
  const Mat6 L = prior.llt().matrixL();
  const SE3 T_mr = stored_is_T_rm ? stored.Inverse() : stored;
  double sum = 0.0;
  const int kDraws = 20000;
  for (int k = 0; k < kDraws; ++k) {
    Vec6 z;
    for (int i = 0; i < 6; ++i) z[i] = n(rng);
    const SE3 truth_state = SE3::Exp(L * z) * stored;
    const SE3 T_mr_true = stored_is_T_rm ? truth_state.Inverse() : truth_state;
    const Vec6 e = (T_mr_true * T_mr.Inverse()).Log();
    sum += e.dot(S.ldlt().solve(e));
  }
  return sum / kDraws;
}

TEST(PoseCovariance, BaselineWorldPoseIsThePriorItself) {
  const SE3 T_wb = FarPose();
  const Mat6 prior = PriorCovariance();
  const Mat6 S = Reported(T_wb, prior, T_wb, T_wb.Adjoint());
  EXPECT_LT((S - prior).norm(), 1e-9 * prior.norm());
  // χ²₆ mean over 20000 draws: standard deviation √(12/20000) = 0.024; bound 4σ.
  EXPECT_NEAR(MonteCarloNees(T_wb, prior, false, S), 6.0, 0.1);
}

TEST(PoseCovariance, KnotPoseIsMappedByTheAdjointOfTheInverse) {
  const SE3 T_rm = FarPose();
  const SE3 T_mr = T_rm.Inverse();
  const Mat6 prior = PriorCovariance();
  const Mat6 S = Reported(T_rm, prior, T_mr, -Mat6::Identity());
  const Mat6 expected = T_mr.Adjoint() * prior * T_mr.Adjoint().transpose();
  EXPECT_LT((S - expected).norm(), 1e-9 * expected.norm());
  EXPECT_NEAR(MonteCarloNees(T_rm, prior, true, S), 6.0, 0.1);
  // The same Σ read in the wrong convention (the state's own, without the map) is far off.
  EXPECT_GT(MonteCarloNees(T_rm, prior, true, prior), 12.0);
}

// The dense path with the lidar information rescaled: scale 1 is ceres::Covariance, and a
// window whose only information is the "lidar" block scales with it.
TEST(PoseCovariance, ScaledDenseCovarianceAndChiSquareScale) {
  const SE3 T_wb = FarPose();
  const Mat6 prior = PriorCovariance();
  SlidingWindow window;
  window.AddPoseState(0, T_wb);
  const ceres::ResidualBlockId block =
      window.AddResidualBlock(PosePrior::FromCovariance(T_wb, prior), nullptr, {0});
  for (const double scale : {1.0, 4.0}) {
    const std::optional<Mat6> S =
        ScaledPoseCovariance(window, 0, {block}, scale, T_wb, T_wb.Adjoint());
    ASSERT_TRUE(S.has_value());
    EXPECT_LT((*S - scale * prior).norm(), 1e-9 * scale * prior.norm());
  }
  // A residual of whitened size 3 in each of 6 components: s = 2·(½·6·9)/6 = 9.
  const Mat6 sqrt_info = SqrtInformationFromCovariance<6>(prior);
  const Vec6 offset = sqrt_info.inverse() * Vec6::Constant(3.0);
  const SE3 mean = SE3::Exp(-offset) * T_wb;
  SlidingWindow shifted;
  shifted.AddPoseState(0, T_wb);
  const ceres::ResidualBlockId far =
      shifted.AddResidualBlock(PosePrior::FromCovariance(mean, prior), nullptr, {0});
  EXPECT_NEAR(LidarChiSquareScale(&shifted.problem(), {far}), 9.0, 1e-9);
  EXPECT_DOUBLE_EQ(LidarChiSquareScale(&shifted.problem(), {}), 1.0);
}

}  // namespace
}  // namespace ctlio::lio
