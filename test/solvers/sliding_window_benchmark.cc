// Time per marginalisation step of SlidingWindow for windows of 2, 5 and 10 SE(3) knots
// (pose, ϖ, ϖ̇ each), 1,000 continuous-time point-to-plane residuals per knot interval
// (ContinuousPointToPlane on gp::GpInterpolator, SPEC §4), SE(3) Singer priors between knots and
// a state prior on the first knot. One step = Marginalize() of the oldest knot: linearise its
// 1,000 lidar residuals + priors, Schur complement, build the MarginalizationPrior, remove the
// blocks. Window construction is excluded from the timing. BM_Solve times one Ceres solve of the
// same window for scale. Report medians (--benchmark_repetitions=5
// --benchmark_report_aggregates_only=true).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/priors/state_prior.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio {
namespace {

constexpr double kDt = 0.1;
constexpr int kPointsPerInterval = 1000;

StateId PoseId(int k) { return 3 * k; }

std::unique_ptr<SlidingWindow> BuildWindow(int knots, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec6 qc = Vec6::Constant(1.0), alpha = Vec6::Zero();
  const gp::SingerModel<6> model(qc, alpha);
  Vec6 velocity;
  velocity << -3.0, 0.2, 0.0, 0.05, -0.02, -0.4;                     // ϖ = −[v; ω]
  auto truth_at = [&](double t) { return SE3::Exp(t * velocity); };  // constant ϖ from identity

  auto window = std::make_unique<SlidingWindow>();
  for (int k = 0; k < knots; ++k) {
    Vec6 noise;
    for (int i = 0; i < 6; ++i) noise[i] = 0.01 * u(rng);
    window->AddPoseState(PoseId(k), SE3::Exp(noise) * truth_at(k * kDt));
    window->AddVectorState(PoseId(k) + 1, Vec6(velocity + 0.05 * noise));
    window->AddVectorState(PoseId(k) + 2, Vec6(Vec6::Zero()));
  }
  Eigen::Matrix<double, 18, 18> P0 = Eigen::Matrix<double, 18, 18>::Identity() * 1e-2;
  window->AddResidualBlock(StatePrior::FromCovariance(truth_at(0.0), velocity, Vec6::Zero(), P0),
                           nullptr, {PoseId(0), PoseId(0) + 1, PoseId(0) + 2});
  for (int k = 0; k + 1 < knots; ++k) {
    const std::vector<StateId> ids = {PoseId(k),     PoseId(k) + 1,     PoseId(k) + 2,
                                      PoseId(k + 1), PoseId(k + 1) + 1, PoseId(k + 1) + 2};
    window->AddResidualBlock(new gp::SingerPrior(model, kDt), nullptr, ids);
    for (int p = 0; p < kPointsPerInterval; ++p) {
      const double tau = (k + 0.5 * (1.0 + u(rng))) * kDt;
      auto interpolator =
          std::make_shared<const gp::GpInterpolator>(model, k * kDt, (k + 1) * kDt, tau);
      PlaneAssociation m;
      const Vec3 p_map(20.0 * u(rng), 20.0 * u(rng), 3.0 * u(rng));
      m.plane_normal = Vec3(u(rng), u(rng), u(rng)).normalized();
      m.plane_point = p_map + m.plane_normal.unitOrthogonal() * u(rng);
      m.point_robot = truth_at(tau) * p_map;
      window->AddResidualBlock(new ContinuousPointToPlane(interpolator, m),
                               new ceres::HuberLoss(0.1), ids);
    }
  }
  return window;
}

void BM_MarginalizeOldestKnot(benchmark::State& state) {
  const int knots = static_cast<int>(state.range(0));
  unsigned seed = 1;
  for (auto _ : state) {
    state.PauseTiming();
    std::unique_ptr<SlidingWindow> window = BuildWindow(knots, seed++);
    state.ResumeTiming();
    const MarginalizationReport report =
        window->Marginalize({PoseId(0), PoseId(0) + 1, PoseId(0) + 2});
    benchmark::DoNotOptimize(report.prior);
    state.PauseTiming();
    window.reset();
    state.ResumeTiming();
  }
  state.counters["residuals_removed"] = kPointsPerInterval + (knots > 1 ? 2 : 1);
}
BENCHMARK(BM_MarginalizeOldestKnot)->Arg(2)->Arg(5)->Arg(10)->Unit(benchmark::kMillisecond);

// The linearisation part alone (evaluating the 1,002 residual blocks with Jacobians and
// accumulating H, b), to split the step's cost.
void BM_LinearizeOldestKnot(benchmark::State& state) {
  const int knots = static_cast<int>(state.range(0));
  std::unique_ptr<SlidingWindow> window = BuildWindow(knots, 1);
  std::vector<ceres::ResidualBlockId> residuals = window->ResidualBlocksOf(PoseId(0));
  std::vector<StateId> ordering = {PoseId(0), PoseId(0) + 1, PoseId(0) + 2};
  if (knots > 1) ordering.insert(ordering.end(), {PoseId(1), PoseId(1) + 1, PoseId(1) + 2});
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  for (auto _ : state) {
    window->Linearize(residuals, ordering, &H, &b);
    benchmark::DoNotOptimize(H.data());
  }
}
BENCHMARK(BM_LinearizeOldestKnot)->Arg(2)->Arg(10)->Unit(benchmark::kMillisecond);

void BM_Solve(benchmark::State& state) {
  const int knots = static_cast<int>(state.range(0));
  unsigned seed = 1;
  for (auto _ : state) {
    state.PauseTiming();
    std::unique_ptr<SlidingWindow> window = BuildWindow(knots, seed++);
    window->options().solver.max_num_iterations = 5;
    state.ResumeTiming();
    benchmark::DoNotOptimize(window->Solve().final_cost);
    state.PauseTiming();
    window.reset();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_Solve)->Arg(2)->Arg(5)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ctlio

BENCHMARK_MAIN();
