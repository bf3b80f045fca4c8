// The calibration warm-up replay (calibration.warmup_replay_s, lio_odometry.h): the first seconds
// are processed again from the estimates they produced, once, and the pipeline that replayed
// them carries on. On tuning sequence medium/100 (16 beams, every 4th firing, both calibrations
// from the wrong start: 20 ms clock offset, 3° / 10 cm extrinsic).
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

sim::SimConfig WrongStart(double duration_s) {
  return testing::WrongCalibrationSequence(sim::Regime::kMedium, duration_s, 0.020);
}

OdometryConfig Calibrating(double warmup_replay_s) {
  OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  config.calibration.warmup_replay_s = warmup_replay_s;
  return config;
}

TEST(WarmupReplay, ReplaysTheSpanOnceFromTheEstimatesItProduced) {
  sim::SimulatedSource source(WrongStart(1.5));
  OdometryConfig config = Calibrating(1.0);
  config.T_imu_lidar = source.ImuFromLidar();  // the perturbed nominal
  LioOdometry odometry(config);
  io::ScanFrame frame;
  int scans = 0, replays = 0;
  int64_t first_begin = 0, previous_end = 0;
  while (source.Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) odometry.AddImu(x);
    const LidarScan scan = lioapp::TakeLidarScan(&frame);
    if (scans == 0) first_begin = scan.begin_ns;
    const ScanResult r = odometry.AddScan(scan);
    ++scans;
    ASSERT_NE(r.status, ScanStatus::kFailed) << r.message;
    if (r.revised_scans > 0) {
      ++replays;
      // The first scan ending 1 s or more after the first one began; every scan before it revised.
      EXPECT_GE(scan.end_ns - first_begin, 1000000000);
      EXPECT_LT(previous_end - first_begin, 1000000000);
      EXPECT_EQ(r.revised_scans, scans - 1);
      EXPECT_EQ(odometry.warmup_results().size(), static_cast<size_t>(scans));
      EXPECT_NE(r.message.find("warm-up replayed"), std::string::npos) << r.message;
    }
    previous_end = scan.end_ns;
  }
  ASSERT_EQ(replays, 1);
  ASSERT_EQ(odometry.results().size(), static_cast<size_t>(scans));
  const std::vector<ScanResult>& live = odometry.warmup_results();
  ASSERT_GE(live.size(), 10u);
  const ScanResult::CalibrationEstimate& warm = live.back().calibration;
  ASSERT_EQ(warm.time_offset_s.size(), 1u);
  ASSERT_EQ(odometry.config().calibration.time_offset_s.size(), 1u);
  EXPECT_EQ(odometry.config().calibration.TimeOffset(0), warm.time_offset_s[0]);
  EXPECT_TRUE(odometry.config().T_imu_lidar.Matrix().isApprox(warm.T_imu_lidar.Matrix(), 0.0));
  EXPECT_EQ(odometry.config().calibration.warmup_replay_s, 0.0);
  // Live, δ starts from 0 towards the true 20 ms; replayed, it starts at the warm-up's estimate
  // (which moved past 10 ms), so the replayed second scan is nearer to it than the live one was.
  EXPECT_GT(warm.time_offset_s[0], 0.010);
  const double replayed = odometry.results()[1].calibration.time_offset_s.at(0);
  const double first_live = live[1].calibration.time_offset_s.at(0);
  EXPECT_LT(std::abs(replayed - warm.time_offset_s[0]),
            std::abs(first_live - warm.time_offset_s[0]));
  // Later scans are the replayed pipeline's, and every call reaches it.
  EXPECT_GT(odometry.num_marginalizations(), 0);
  EXPECT_TRUE(odometry.initialised());
}

// RunOdometry's two trajectories: the reported one takes the replayed estimates of the warm-up
// scans; the live one (what AddScan returned, scan by scan) continues through the replay in its
// own map frame (the replay's first scan is placed with the warm-up's extrinsic), so its ATE is
// that of a run without the replay, not broken by a jump of the frame (3° / 10 cm here).
TEST(WarmupReplay, LiveTrajectoryContinuesThroughTheReplay) {
  sim::SimulatedSource with_source(WrongStart(4.0));
  const lioapp::RunSummary with = lioapp::RunOdometry(with_source, Calibrating(2.0));
  sim::SimulatedSource without_source(WrongStart(4.0));
  const lioapp::RunSummary without = lioapp::RunOdometry(without_source, Calibrating(0.0));
  ASSERT_EQ(with.failed, 0) << with.first_failure;
  ASSERT_EQ(without.failed, 0) << without.first_failure;
  EXPECT_GE(with.warmup_replayed_scans, 19);
  EXPECT_EQ(without.warmup_replayed_scans, 0);
  ASSERT_TRUE(with.ate && with.live_ate && without.ate && without.live_ate);
  EXPECT_EQ(with.scans.size(), without.scans.size());
  EXPECT_EQ(with.trajectory.size(), with.live_trajectory.size());
  EXPECT_TRUE(with.dense.empty());  // no trajectory_rate_hz
  // Without a replay the live trajectory is the trajectory; with one they differ over the span.
  EXPECT_EQ(without.live_ate->rmse, without.ate->rmse);
  EXPECT_NE(with.live_ate->rmse, with.ate->rmse);
  EXPECT_LT(with.live_ate->rmse, 1.25 * without.ate->rmse);
  // Both within the accuracy of a calibrated run on this sequence (~1 cm), not a frame apart.
  EXPECT_LT(with.ate->rmse, 0.03);
  EXPECT_LT(with.live_ate->rmse, 0.03);
}

TEST(WarmupReplay, NothingIsKeptWithoutAnEstimatedCalibration) {
  sim::SimulatedSource source(WrongStart(1.2));
  OdometryConfig config = Calibrating(1.0);
  config.calibration.estimate_time_offset = false;
  config.calibration.estimate_extrinsic = false;
  const lioapp::RunSummary run = lioapp::RunOdometry(source, config);
  EXPECT_EQ(run.warmup_replayed_scans, 0);
  for (const ScanResult& r : run.scans) EXPECT_EQ(r.revised_scans, 0);
}

}  // namespace
}  // namespace ctlio::lio
