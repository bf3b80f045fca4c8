// The calibration warm-up replay (calibration.warmup_replay_s, calibrating_odometry.h): the first
// seconds are processed again from the estimates they produced, once, and the pipeline that
// replayed them carries on. On tuning sequence medium/100 (16 beams, every 4th firing, both
// calibrations from the wrong start: 20 ms clock offset, 3° / 10 cm extrinsic).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/calibrating_odometry.h"
#include "ctlio/solvers/lio/state_keys.h"
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

// The calibrating config with the replay in two passes, the last one held.
OdometryConfig TwoPassesLastHeld(const sim::SimulatedSource& source) {
  OdometryConfig config = Calibrating(1.0);
  config.calibration.warmup_replay_passes = 2;
  config.calibration.warmup_replay_hold = true;
  config.T_imu_lidar = source.ImuFromLidar();  // the perturbed nominal
  return config;
}

// Feeds every frame of `source` to `odometry`, each scan's status checked: the number of scans,
// the index of the scan that replayed the warm-up (-1: none) and its result.
void FeedAll(sim::SimulatedSource* source, CalibratingOdometry* odometry, int* scans,
             int* replayed_at, ScanResult* replay) {
  io::ScanFrame frame;
  *scans = 0;
  *replayed_at = -1;
  while (source->Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) odometry->AddImu(x);
    const ScanResult r = odometry->AddScan(lioapp::TakeLidarScan(&frame));
    ASSERT_NE(r.status, ScanStatus::kFailed) << r.message;
    if (r.revised_scans > 0) {
      *replayed_at = *scans;
      *replay = r;
    }
    ++*scans;
  }
}

TEST(WarmupReplay, ReplaysTheSpanOnceFromTheEstimatesItProduced) {
  sim::SimulatedSource source(WrongStart(1.5));
  OdometryConfig config = Calibrating(1.0);
  config.T_imu_lidar = source.ImuFromLidar();  // the perturbed nominal
  CalibratingOdometry odometry(config);
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
  const std::deque<ScanResult>& live = odometry.warmup_results();
  ASSERT_GE(live.size(), 10u);
  const ScanResult::CalibrationEstimate& warm = live.back().calibration;
  ASSERT_EQ(warm.time_offset_s.size(), 1u);
  ASSERT_EQ(odometry.config().calibration.time_offset_s.size(), 1u);
  EXPECT_EQ(odometry.config().calibration.TimeOffset(0), warm.time_offset_s[0]);
  // The extrinsic starts at the warm-up's estimate along the coordinates the observability check
  // found observable, at the configured (nominal) value along the others: in calibration.csv's
  // chart T = Exp([ρ; φ])·T_nominal.
  ASSERT_EQ(warm.unobservable.size(), 7u);
  EXPECT_FALSE(warm.unobservable[0]);  // δ: observable after 1 s of medium motion
  const SE3& nominal = config.T_imu_lidar;
  const Vec6 xi_warm = (warm.T_imu_lidar * nominal.Inverse()).Log();
  const Vec6 xi_start = (odometry.config().T_imu_lidar * nominal.Inverse()).Log();
  int observable = 0;
  for (int k = 0; k < 6; ++k) {
    const bool unobservable = warm.unobservable[static_cast<size_t>(1 + k)];
    observable += unobservable ? 0 : 1;
    EXPECT_NEAR(xi_start[k], unobservable ? 0.0 : xi_warm[k], 1e-9) << k;
  }
  EXPECT_GE(observable, 3);  // the rotation at least
  EXPECT_EQ(odometry.config().calibration.warmup_replay_s, 0.0);
  // Live, δ starts from 0 towards the true 20 ms; replayed, it starts at the warm-up's estimate
  // (which moved past 10 ms), so the replayed second scan is nearer to it than the live one was.
  EXPECT_GT(warm.time_offset_s[0], 0.010);
  const double replayed = odometry.results()[1].calibration.time_offset_s.at(0);
  const double first_live = live[1].calibration.time_offset_s.at(0);
  EXPECT_LT(std::abs(replayed - warm.time_offset_s[0]),
            std::abs(first_live - warm.time_offset_s[0]));
  // Without the hold the replay refines C_mi with the extrinsic, as the live pipeline does.
  EXPECT_FALSE(odometry.config().calibration.hold_gravity);
  EXPECT_FALSE(odometry.window().IsStateConstant(kGravityKey));
  // Later scans are the replayed pipeline's, and every call reaches it.
  EXPECT_GT(odometry.num_marginalizations(), 0);
  EXPECT_TRUE(odometry.initialised());
}

// A bounded result history (OdometryConfig::kept_results) still keeps the whole warm-up span
// until the replay, which hands every replayed result of it to the caller; then the bound holds.
TEST(WarmupReplay, BoundedHistoryKeepsTheSpanUntilTheReplay) {
  sim::SimulatedSource source(WrongStart(1.5));
  OdometryConfig config = Calibrating(1.0);
  config.T_imu_lidar = source.ImuFromLidar();
  config.kept_results = 3;
  CalibratingOdometry odometry(config);
  io::ScanFrame frame;
  size_t scans = 0;
  bool replayed = false;
  while (source.Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) odometry.AddImu(x);
    const ScanResult r = odometry.AddScan(lioapp::TakeLidarScan(&frame));
    ++scans;
    ASSERT_NE(r.status, ScanStatus::kFailed) << r.message;
    if (r.revised_scans > 0) {
      replayed = true;
      EXPECT_EQ(odometry.results().size(), scans);  // the span, replayed, and this scan
      EXPECT_EQ(odometry.warmup_results().size(), scans);
      EXPECT_EQ(odometry.results().back().t_ns, r.t_ns);
    } else {
      EXPECT_EQ(odometry.results().size(), replayed ? 3u : scans) << "scan " << scans;
    }
  }
  EXPECT_TRUE(replayed);
  EXPECT_GE(scans, 14u);
}

// Two passes, the last one held (calibration.warmup_replay_passes / warmup_replay_hold): the
// second pass starts from where the first ended, not from the live estimates, and solves the span
// with the calibration held at those values; the scans after the span move it again.
TEST(WarmupReplay, LaterPassStartsFromThePreviousOneAndTheLastHoldsTheSpan) {
  sim::SimulatedSource source(WrongStart(1.6));
  CalibratingOdometry odometry(TwoPassesLastHeld(source));
  int scans = 0, replayed_at = -1;
  ScanResult replay;
  ASSERT_NO_FATAL_FAILURE(FeedAll(&source, &odometry, &scans, &replayed_at, &replay));
  ASSERT_GE(replayed_at, 9);
  EXPECT_NE(replay.message.find("2 passes"), std::string::npos) << replay.message;
  EXPECT_NE(replay.message.find("held over the span"), std::string::npos) << replay.message;
  ASSERT_LE(replayed_at + 4, scans);
  // The carrying-on pipeline started from the first pass's estimates: nearer the true 20 ms
  // than the live warm-up's last estimate (which its first pass started from).
  const double live = odometry.warmup_results().back().calibration.time_offset_s.at(0);
  const double start = odometry.config().calibration.TimeOffset(0);
  EXPECT_NE(start, live);
  EXPECT_LT(std::abs(start - 0.020), std::abs(live - 0.020));
  const SE3& T_start = odometry.config().T_imu_lidar;
  const std::deque<ScanResult>& results = odometry.results();
  ASSERT_EQ(results.size(), static_cast<size_t>(scans));
  for (int i = 1; i <= replayed_at; ++i) {
    const ScanResult::CalibrationEstimate& c = results[static_cast<size_t>(i)].calibration;
    ASSERT_EQ(c.held.size(), 7u) << "scan " << i;  // δ_0, ρ_xyz, φ_xyz
    for (const bool h : c.held) EXPECT_TRUE(h) << "scan " << i;
    // σ_hold = σ_prior / 1e4: 3 µs, 20 µm, 0.03 mdeg.
    EXPECT_NEAR(c.time_offset_s.at(0), start, 1e-5) << "scan " << i;
    EXPECT_LT((c.T_imu_lidar.translation() - T_start.translation()).norm(), 1e-4) << "scan " << i;
    EXPECT_LT((c.T_imu_lidar * T_start.Inverse()).Log().tail<3>().norm(), 1e-5) << "scan " << i;
  }
  double moved = 0.0;
  for (size_t i = static_cast<size_t>(replayed_at) + 1; i < results.size(); ++i) {
    EXPECT_TRUE(results[i].calibration.held.empty()) << "scan " << i;
    moved = std::max(moved, std::abs(results[i].calibration.time_offset_s.at(0) - start));
  }
  EXPECT_GT(moved, 1e-5);  // released: the data move it again
  // C_mi stays held in the pipeline started from estimated values (the first scan placed with
  // them), although the extrinsic is estimated; the live one refined it.
  EXPECT_TRUE(odometry.config().calibration.hold_gravity);
  EXPECT_TRUE(odometry.window().IsStateConstant(kGravityKey));
}

// Two passes, the last one frozen (calibration.warmup_replay_freeze): the second pass and
// everything after it run with the values the first pass ended with as known values (no
// calibration states), which is exactly the estimator configured with those values; every result
// from the replay on reports them, held, with the σ the first pass ended with.
TEST(WarmupReplay, FrozenLastPassIsTheEstimatorOfTheValuesItFroze) {
  sim::SimulatedSource source(WrongStart(1.6));
  OdometryConfig config = TwoPassesLastHeld(source);
  config.calibration.warmup_replay_hold = false;
  config.calibration.warmup_replay_freeze = true;
  CalibratingOdometry odometry(config);
  int scans = 0, replayed_at = -1;
  ScanResult replay;
  ASSERT_NO_FATAL_FAILURE(FeedAll(&source, &odometry, &scans, &replayed_at, &replay));
  ASSERT_GE(replayed_at, 9);
  ASSERT_LE(replayed_at + 4, scans);
  EXPECT_NE(replay.message.find("frozen"), std::string::npos) << replay.message;
  // The carrying-on pipeline: known values, the first pass's estimates (not the live ones).
  const OdometryConfig& frozen = odometry.config();
  EXPECT_FALSE(frozen.calibration.any());
  EXPECT_FALSE(odometry.window().HasState(kExtrinsicKey));
  EXPECT_FALSE(odometry.window().HasState(TimeOffsetKey(0)));
  const double live = odometry.warmup_results().back().calibration.time_offset_s.at(0);
  const double value = frozen.calibration.TimeOffset(0);
  EXPECT_LT(std::abs(value - 0.020), std::abs(live - 0.020));
  EXPECT_GT((frozen.T_imu_lidar.translation() - config.T_imu_lidar.translation()).norm(), 0.01);
  const std::deque<ScanResult>& results = odometry.results();
  ASSERT_EQ(results.size(), static_cast<size_t>(scans));
  const ScanResult::CalibrationEstimate& first = results.front().calibration;
  ASSERT_EQ(first.time_offset_sigma_s.size(), 1u);
  EXPECT_GT(first.time_offset_sigma_s[0], 0.0);
  EXPECT_LT(first.time_offset_sigma_s[0], config.calibration.time_offset_prior_sigma_s);
  EXPECT_GT(first.extrinsic_sigma.minCoeff(), 0.0);
  for (size_t i = 0; i < results.size(); ++i) {
    const ScanResult::CalibrationEstimate& c = results[i].calibration;
    EXPECT_EQ(c.held, std::vector<bool>(7, true)) << "scan " << i;  // δ_0, ρ_xyz, φ_xyz
    EXPECT_EQ(c.time_offset_s.at(0), value) << "scan " << i;
    EXPECT_TRUE(c.has_extrinsic);
    EXPECT_EQ(c.T_imu_lidar.Matrix(), frozen.T_imu_lidar.Matrix()) << "scan " << i;
    EXPECT_EQ(c.time_offset_sigma_s, first.time_offset_sigma_s) << "scan " << i;
    EXPECT_EQ(c.extrinsic_sigma, first.extrinsic_sigma) << "scan " << i;
  }
  // The same data through a pipeline configured with the frozen values: the same poses.
  OdometryConfig known = frozen;
  known.kept_results = 0;
  CalibratingOdometry reference(known);
  sim::SimulatedSource again(WrongStart(1.6));
  int reference_scans = 0, none = -1;
  ASSERT_NO_FATAL_FAILURE(FeedAll(&again, &reference, &reference_scans, &none, &replay));
  EXPECT_EQ(none, -1);
  ASSERT_EQ(reference_scans, scans);
  for (size_t i = 0; i < results.size(); ++i) {
    EXPECT_LT((results[i].T_mr.Matrix() - reference.results()[i].T_mr.Matrix()).norm(), 1e-9)
        << "scan " << i;
  }
}

// Slow motion (translation only, tuning sequence slow/100): the observability check finds the
// lever arm unobservable, so its estimate after the warm-up is drift. The replay then starts
// those coordinates from the configured (nominal) value and does not hold them; it holds the
// others.
TEST(WarmupReplay, UnobservableCoordinatesStartFromTheConfigAndAreNotHeld) {
  sim::SimulatedSource source(testing::WrongCalibrationSequence(sim::Regime::kSlow, 1.6, 0.020));
  const OdometryConfig config = TwoPassesLastHeld(source);
  const SE3 nominal = config.T_imu_lidar;
  CalibratingOdometry odometry(config);
  int scans = 0, replayed_at = -1;
  ScanResult replay;
  ASSERT_NO_FATAL_FAILURE(FeedAll(&source, &odometry, &scans, &replayed_at, &replay));
  ASSERT_GE(replayed_at, 9);
  // Which coordinates the last pass held: the same on every scan of the span.
  const std::vector<bool> held = odometry.results()[1].calibration.held;
  ASSERT_EQ(held.size(), 7u);
  for (int i = 2; i <= replayed_at; ++i) {
    EXPECT_EQ(odometry.results()[static_cast<size_t>(i)].calibration.held, held) << "scan " << i;
  }
  EXPECT_FALSE(held[1] && held[2] && held[3]) << "the lever arm is not observable here";
  // Not held = unobservable when the pass started = started at the nominal value.
  const Vec6 xi_start = (odometry.config().T_imu_lidar * nominal.Inverse()).Log();
  const Vec6 xi_end =
      (odometry.results()[static_cast<size_t>(replayed_at)].calibration.T_imu_lidar *
       nominal.Inverse())
          .Log();
  int free = 0;
  for (int k = 0; k < 6; ++k) {
    if (held[static_cast<size_t>(1 + k)]) {
      EXPECT_NEAR(xi_end[k], xi_start[k], 1e-4) << k;  // held over the span
    } else {
      ++free;
      EXPECT_NEAR(xi_start[k], 0.0, 1e-9) << k;
    }
  }
  EXPECT_GE(free, 1);
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
