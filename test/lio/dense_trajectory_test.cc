// The dense trajectories (RunOptions::trajectory_rate_hz): at 100 Hz over a short sparse
// simulated sequence the live one (LioOdometry::SampleNewestInterval) has a pose every 10 ms and
// ends every interval at the scan pose; the one from the final estimates (TakeFinalTrajectory)
// has no jump at the scan boundaries; both follow the truth between the scans as closely as the
// scan poses do.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "common/dense_trajectory_checks.h"
#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

TEST(DenseTrajectory, EndsAtTheScanPosesAndFollowsTheTruth) {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = 1.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    OdometryConfig config = testing::SimLioConfig();
    config.method = m;
    sim::SimulatedSource source(c);
    lioapp::RunOptions options;
    options.trajectory_rate_hz = 100.0;
    const lioapp::RunSummary run = lioapp::RunOdometry(source, config, options);
    ASSERT_EQ(run.failed, 0) << run.first_failure;
    const auto& dense = run.dense;
    // ~100 poses over 0.9 s of estimated intervals plus the first pose.
    EXPECT_GE(dense.size(), 80u);
    EXPECT_EQ(run.dense_live.size(), dense.size());
    std::vector<int64_t> boundaries;
    for (size_t i = 1; i + 1 < run.trajectory.size(); ++i) {
      boundaries.push_back(run.trajectory[i].t_ns);
    }
    EXPECT_LE(testing::MaxBoundaryStepRatio(dense, boundaries), 1.5) << LioMethodName(m);
    // The criterion sees the live trajectory's jumps (measured 7.9 Singer-LIO, 1.8 baseline,
    // against 1.01 / 0.94 for the final one).
    if (m == LioMethod::kSingerLio) {
      EXPECT_GT(testing::MaxBoundaryStepRatio(run.dense_live, boundaries), 3.0);
    }
    // A pose every 10 ms, and every scan pose in the dense trajectory, exactly.
    ASSERT_NO_FATAL_FAILURE(testing::ExpectDenseThroughTheScanPoses(run, 10'000'000));
    // Between the scans it tracks the truth about as well as at the scans (a straight line between
    // scan poses would be off by the motion within 0.1 s).
    const auto truth = source.GroundTruth();
    ASSERT_TRUE(truth && run.ate);
    for (const auto* d : {&dense, &run.dense_live}) {
      const lioapp::AteResult dense_ate = lioapp::EvaluateAte(*d, *truth);
      EXPECT_LT(dense_ate.rmse, 2.0 * run.ate->rmse + 0.005) << LioMethodName(m);
    }
  }
}

}  // namespace
}  // namespace ctlio::lio
