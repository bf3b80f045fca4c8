// Nonlinear SE(3) sliding window: a trajectory sampled from the SE(3) Singer prior itself
// (gp::SingerPrior, SPEC §2) observed by noisy pose measurements (PosePrior). A window of 4 knots
// marginalises the oldest knot (pose, ϖ, ϖ̇ at once) after every step. Over Monte-Carlo runs with
// fixed seeds the window's estimate of the newest knot must
//   (a) have an error within 1% of the full batch solution's error (same data, no
//       marginalisation), and be close to the batch estimate itself;
//   (b) be consistent: mean NEES of the 18-dim knot state inside the two-sided 95% χ² interval.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <iostream>
#include <random>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/factors/priors/state_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio {
namespace {

using Vec18 = Eigen::Matrix<double, 18, 1>;
using Mat18 = Eigen::Matrix<double, 18, 18>;

constexpr double kDt = 0.1;
constexpr int kKnots = 20;
constexpr int kWindowKnots = 4;
constexpr int kRuns = 20;

gp::SingerModel<6> Model() {
  Vec6 qc, alpha;
  qc << 1.0, 1.0, 0.5, 0.2, 0.2, 0.5;  // [ρ; φ] axes
  alpha << 0.0, 0.0, 0.0, 0.5, 0.5, 0.5;
  return gp::SingerModel<6>(qc, alpha);
}

Vec18 Sample(std::mt19937& rng, const Mat18& covariance) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec18 z;
  for (int i = 0; i < 18; ++i) z[i] = n(rng);
  return Eigen::LLT<Mat18>(covariance).matrixL() * z;
}

// Inverse of the local variables of knot_state.h: given γ_{k+1} and T_k, the knot k+1.
gp::KnotState FromLocal(const SE3& T_k, const Vec18& gamma) {
  const Vec6 xi = gamma.head<6>();
  const Mat6 J = se3::LeftJacobian(xi);
  gp::KnotState s;
  s.pose = SE3::Exp(xi) * T_k;
  s.velocity = J * gamma.segment<6>(6);  // γ2 = J⁻¹ϖ
  // γ3 = ½ϖ^⋏J⁻¹ϖ + J⁻¹ϖ̇  ⇒  ϖ̇ = J(γ3 − ½ϖ^⋏γ2).
  s.acceleration = J * (gamma.tail<6>() - 0.5 * se3::CurlyHat(s.velocity) * gamma.segment<6>(6));
  return s;
}

// State ids: knot k has pose 3k, ϖ 3k+1, ϖ̇ 3k+2.
StateId PoseId(int k) { return 3 * k; }

void AddKnot(SlidingWindow* w, int k, const gp::KnotState& x) {
  w->AddPoseState(PoseId(k), x.pose);
  w->AddVectorState(PoseId(k) + 1, x.velocity);
  w->AddVectorState(PoseId(k) + 2, x.acceleration);
}

gp::KnotState ReadKnot(const SlidingWindow& w, int k) {
  return gp::ReadKnotState(w.State(PoseId(k)), w.State(PoseId(k) + 1), w.State(PoseId(k) + 2));
}

// x_true ⊟ x_est in the window's tangent convention (left perturbation).
Vec18 Error(const gp::KnotState& truth, const gp::KnotState& estimate) {
  Vec18 e;
  e.head<6>() = (truth.pose * estimate.pose.Inverse()).Log();
  e.segment<6>(6) = truth.velocity - estimate.velocity;
  e.tail<6>() = truth.acceleration - estimate.acceleration;
  return e;
}

struct RunResult {
  Vec18 window_error, batch_error, window_minus_batch;
  double window_nees = 0.0;  // of the window's newest knot
  int marginalizations = 0;
};

RunResult RunMonteCarlo(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const gp::SingerModel<6> model = Model();
  const Mat18 Q = model.Covariance(kDt);
  const Mat18 Phi = model.Transition(kDt);

  // Truth sampled from the prior: γ_{k+1} = Φγ_k + w, w ~ N(0, Q), γ_k = [0; ϖ_k; ϖ̇_k].
  std::vector<gp::KnotState> truth(kKnots);
  truth[0].pose = SE3::Exp((Vec6() << 1.0, -2.0, 0.5, 0.3, -0.2, 1.0).finished());
  truth[0].velocity << -2.0, 0.0, 0.0, 0.0, 0.0, -0.5;  // ϖ = −[v; ω]
  truth[0].acceleration.setZero();
  for (int k = 0; k + 1 < kKnots; ++k) {
    Vec18 gamma_k;
    gamma_k << Vec6::Zero(), truth[k].velocity, truth[k].acceleration;
    truth[k + 1] = FromLocal(truth[k].pose, Phi * gamma_k + Sample(rng, Q));
  }

  // Initial-state prior: truth ~ N(x̄₀, P₀) (x̄₀ = truth ⊟ sample).
  Vec18 p0_sigma;
  p0_sigma << Vec6::Constant(0.05), Vec6::Constant(0.1), Vec6::Constant(0.3);
  const Mat18 P0 = p0_sigma.cwiseAbs2().asDiagonal();
  const Vec18 d0 = Sample(rng, P0);
  const SE3 pose0 = SE3::Exp(-d0.head<6>()) * truth[0].pose;
  const Vec6 vel0 = truth[0].velocity - d0.segment<6>(6);
  const Vec6 acc0 = truth[0].acceleration - d0.tail<6>();
  // Pose measurements T_m = Exp(m)·T_true, m ~ N(0, R).
  Vec6 r_sigma;
  r_sigma << 0.05, 0.05, 0.05, 0.02, 0.02, 0.02;
  const Mat6 R = r_sigma.cwiseAbs2().asDiagonal();
  std::vector<SE3> measured(kKnots);
  for (int k = 0; k < kKnots; ++k) {
    Vec6 m;
    for (int i = 0; i < 6; ++i) m[i] = r_sigma[i] * n(rng);
    measured[k] = SE3::Exp(m) * truth[k].pose;
  }

  SlidingWindow window, batch;
  for (SlidingWindow* w : {&window, &batch}) {
    w->options().solver.max_num_iterations = 30;
    w->options().solver.function_tolerance = 1e-12;
    w->options().solver.gradient_tolerance = 1e-14;
    w->options().solver.parameter_tolerance = 1e-12;
  }
  RunResult result;
  gp::KnotState guess{pose0, vel0, acc0};
  for (int k = 0; k < kKnots; ++k) {
    if (k > 0) {
      // Constant-velocity extrapolation of the newest estimate (Ṫ = ϖ^T).
      const gp::KnotState prev = ReadKnot(window, k - 1);
      guess.pose = SE3::Exp(kDt * prev.velocity) * prev.pose;
      guess.velocity = prev.velocity;
      guess.acceleration.setZero();
    }
    for (SlidingWindow* w : {&window, &batch}) {
      AddKnot(w, k, guess);
      if (k == 0) {
        w->AddResidualBlock(StatePrior::FromCovariance(pose0, vel0, acc0, P0), nullptr,
                            {PoseId(0), PoseId(0) + 1, PoseId(0) + 2});
      } else {
        w->AddResidualBlock(new gp::SingerPrior(model, kDt), nullptr,
                            {PoseId(k - 1), PoseId(k - 1) + 1, PoseId(k - 1) + 2, PoseId(k),
                             PoseId(k) + 1, PoseId(k) + 2});
      }
      w->AddResidualBlock(PosePrior::FromCovariance(measured[k], R), nullptr, {PoseId(k)});
    }
    const ceres::Solver::Summary summary = window.Solve();
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
    if (k >= kWindowKnots) {
      const int oldest = k - kWindowKnots;
      const MarginalizationReport report =
          window.Marginalize({PoseId(oldest), PoseId(oldest) + 1, PoseId(oldest) + 2});
      EXPECT_EQ(report.marginalized_rank, 18);
      EXPECT_EQ(report.prior_rank, 18);
      ++result.marginalizations;
    }
  }
  EXPECT_TRUE(batch.Solve().IsSolutionUsable());
  const int last = kKnots - 1;
  const std::vector<StateId> ids = {PoseId(last), PoseId(last) + 1, PoseId(last) + 2};
  const gp::KnotState w_est = ReadKnot(window, last), b_est = ReadKnot(batch, last);
  result.window_error = Error(truth[last], w_est);
  result.batch_error = Error(truth[last], b_est);
  result.window_minus_batch = Error(b_est, w_est);
  const Mat18 Pw = window.Covariance(ids);
  result.window_nees = result.window_error.dot(Pw.ldlt().solve(result.window_error));
  return result;
}

TEST(SlidingWindowSe3, MatchesBatchAndIsConsistent) {
  double window_sq = 0.0, batch_sq = 0.0, diff_sq = 0.0;
  double window_nees = 0.0;
  Vec18 scale;  // normalise the error components by the measurement/prior scales
  scale << Vec6::Constant(1.0 / 0.05), Vec6::Constant(1.0), Vec6::Constant(1.0);
  for (int run = 0; run < kRuns; ++run) {
    const RunResult r = RunMonteCarlo(1000 + run);
    EXPECT_EQ(r.marginalizations, kKnots - kWindowKnots);
    window_sq += r.window_error.cwiseProduct(scale).squaredNorm();
    batch_sq += r.batch_error.cwiseProduct(scale).squaredNorm();
    diff_sq += r.window_minus_batch.cwiseProduct(scale).squaredNorm();
    window_nees += r.window_nees / kRuns;
  }
  const double ratio = std::sqrt(window_sq / batch_sq);
  std::cout << "RMS error window/batch = " << ratio
            << ", RMS |window - batch| / RMS batch error = " << std::sqrt(diff_sq / batch_sq)
            << ", mean NEES " << window_nees << " (18 dof, " << kRuns << " runs)\n";
  EXPECT_NEAR(ratio, 1.0, 0.01);
  EXPECT_LT(std::sqrt(diff_sq / batch_sq), 0.05);
  // Mean of kRuns independent χ²₁₈ values: the two-sided 95% interval of χ²₃₆₀/20 is
  // [15.47, 20.72] (exact quantiles).
  EXPECT_GT(window_nees, 15.47);
  EXPECT_LT(window_nees, 20.72);
}

}  // namespace
}  // namespace ctlio
