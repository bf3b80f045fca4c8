// Batch versus window (issue 43): the covariance the odometry reports for its newest pose
// (pose_covariance.h, ceres::Covariance of the window with its marginalisation prior) must equal
// the filtering covariance of a batch smoother holding every factor so far, on a short, nearly
// linear SE(3) sequence: GP knots (gp::SingerPrior) observed by pose measurements (PosePrior),
// a window of two knots that marginalises the older one at every step as the odometry does
// (window.knots: 2). The Schur-complement prior and ceres::Covariance then describe the same
// linearisation up to the estimate's small moves after marginalisation (first-estimate
// Jacobians).
#include <gtest/gtest.h>

#include <random>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/factors/priors/state_prior.h"
#include "ctlio/solvers/lio/pose_covariance.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {
namespace {

constexpr double kDt = 0.1;
constexpr int kKnots = 12;

StateId Id(int k, int part) { return 3 * k + part; }  // pose, ϖ, ϖ̇

void AddKnot(SlidingWindow* w, int k, const SE3& T_rm, const Vec6& velocity) {
  w->AddPoseState(Id(k, 0), T_rm);
  w->AddVectorState(Id(k, 1), velocity);
  w->AddVectorState(Id(k, 2), Vec6::Zero());
}

// The factors of step k (the initial prior at k = 0, else the motion prior from k − 1) and the
// pose measurement of knot k.
void AddFactors(SlidingWindow* w, int k, const gp::SingerModel<6>& model, const SE3& T0,
                const Vec6& v0, const SE3& measured, const Mat6& R) {
  if (k == 0) {
    Eigen::Matrix<double, 18, 1> sigma;
    sigma << Vec6::Constant(0.01), Vec6::Constant(0.1), Vec6::Constant(0.3);
    w->AddResidualBlock(
        StatePrior::FromCovariance(T0, v0, Vec6::Zero(), sigma.cwiseAbs2().asDiagonal()), nullptr,
        {Id(0, 0), Id(0, 1), Id(0, 2)});
  } else {
    w->AddResidualBlock(new gp::SingerPrior(model, kDt), nullptr,
                        {Id(k - 1, 0), Id(k - 1, 1), Id(k - 1, 2), Id(k, 0), Id(k, 1), Id(k, 2)});
  }
  w->AddResidualBlock(PosePrior::FromCovariance(measured, R), nullptr, {Id(k, 0)});
}

Mat6 NewestCovariance(SlidingWindow* w, int k) {
  const SE3 T_rm = w->Pose(Id(k, 0));
  const std::optional<Mat6> S =
      PoseCovariance(&w->problem(), w->State(Id(k, 0)), T_rm.Inverse(), -Mat6::Identity());
  EXPECT_TRUE(S.has_value());
  return S.value_or(Mat6::Identity());
}

TEST(WindowCovariance, NewestPoseMatchesBatchFilteringCovariance) {
  Vec6 qc, alpha;
  qc << 1.0, 1.0, 1.0, 0.5, 0.5, 0.5;
  alpha << 0.0, 0.0, 0.0, 1.0, 1.0, 1.0;
  const gp::SingerModel<6> model(qc, alpha);
  // Truth: a constant twist (ϖ = −[v; ω], SPEC §1) from a pose away from the origin.
  const SE3 T0 = SE3::Exp((Vec6() << 2.0, -1.0, 0.5, 0.3, -0.2, 0.8).finished());
  const Vec6 v0 = (Vec6() << -1.0, 0.2, 0.0, 0.0, 0.1, -0.4).finished();
  Vec6 r_sigma;
  r_sigma << 0.01, 0.01, 0.01, 0.002, 0.002, 0.002;
  const Mat6 R = r_sigma.cwiseAbs2().asDiagonal();
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  std::vector<SE3> measured;
  for (int k = 0; k < kKnots; ++k) {
    Vec6 m;
    for (int i = 0; i < 6; ++i) m[i] = r_sigma[i] * n(rng);
    measured.push_back(SE3::Exp(m) * SE3::Exp(k * kDt * v0) * T0);
  }

  SlidingWindow window;
  double worst = 0.0;
  for (int k = 0; k < kKnots; ++k) {
    if (k >= 2) window.Marginalize({Id(k - 2, 0), Id(k - 2, 1), Id(k - 2, 2)});
    AddKnot(&window, k, measured[k], v0);
    AddFactors(&window, k, model, T0, v0, measured[k], R);
    ASSERT_TRUE(window.Solve().IsSolutionUsable());
    const Mat6 S_window = NewestCovariance(&window, k);

    SlidingWindow batch;  // every factor up to k, nothing marginalised
    for (int j = 0; j <= k; ++j) {
      AddKnot(&batch, j, measured[j], v0);
      AddFactors(&batch, j, model, T0, v0, measured[j], R);
    }
    ASSERT_TRUE(batch.Solve().IsSolutionUsable());
    const Mat6 S_batch = NewestCovariance(&batch, k);
    // Relative difference in the metric of the batch covariance: ‖L⁻¹(S_w − S_b)L⁻ᵀ‖.
    const Eigen::LLT<Mat6> L(S_batch);
    const Mat6 A = L.matrixL().solve(Mat6(S_window - S_batch));
    const Mat6 D = L.matrixL().solve(Mat6(A.transpose()));
    worst = std::max(worst, D.norm());
  }
  // Measured 1e-? here; exact in the linear case (sliding_window_test).
  std::printf("worst %g\n", worst);
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace ctlio::lio
