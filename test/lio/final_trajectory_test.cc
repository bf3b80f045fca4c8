// The dense trajectory from the final estimates (final_trajectory.h, LioOdometry::
// TakeFinalTrajectory): on a short sparse simulated sequence, for Singer-LIO (GP interpolation)
// and the baseline (IMU propagation anchored at both states), it passes exactly through the
// final estimate of every state, is time ordered over [first state, last state], and is
// continuous at the scan boundaries (the criterion of the live-stitched trajectory's jumps); and
// the part itself writes no segment across a failed scan.
#include "ctlio/solvers/lio/final_trajectory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <vector>

#include "common/dense_trajectory_checks.h"
#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/state_keys.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

sim::SimConfig ShortSequence() { return testing::ShortSparseSequence(); }

TEST(FinalTrajectory, PassesThroughTheFinalStatesContinuously) {
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    SCOPED_TRACE(LioMethodName(m));
    sim::SimulatedSource source(ShortSequence());
    OdometryConfig config = testing::SimLioConfig();
    config.method = m;
    config.T_imu_lidar = source.ImuFromLidar();
    if (const auto g = source.Gravity()) config.gravity = *g;
    LioOdometry odometry(config);
    odometry.SampleFinalTrajectory(200.0);
    // The value of every state as last seen after a scan: its final estimate once it has left
    // the window (nothing changes it between the scan and its marginalisation), and the current
    // one of those still in the window at the end. State n is the n-th scan's (one per scan),
    // its pose block id 8n (state_keys.h), T_rm for the GP knots, T_wb for the baseline.
    std::map<int64_t, SE3> last_seen;
    std::vector<int64_t> scan_ends;
    FinalTrajectory::Samples dense;
    io::ScanFrame frame;
    while (source.Next(&frame)) {
      for (const io::ImuSample& x : frame.imu) odometry.AddImu(x);
      const ScanResult r = odometry.AddScan(lioapp::TakeLidarScan(&frame));
      ASSERT_NE(r.status, ScanStatus::kFailed) << r.message;
      const int64_t n = static_cast<int64_t>(scan_ends.size());
      scan_ends.push_back(r.t_ns);
      for (int64_t i = 0; i <= n; ++i) {
        const StateId pose = KnotKeys::ForKnot(i).pose;
        ASSERT_EQ(pose, NavStateKeys::ForState(i).pose);
        if (!odometry.window().HasState(pose)) continue;
        const SE3 T = odometry.window().Pose(pose);
        last_seen[scan_ends[static_cast<size_t>(i)]] = m == LioMethod::kImuInput ? T : T.Inverse();
      }
      for (auto& s : odometry.TakeFinalTrajectory()) dense.push_back(s);
    }
    for (auto& s : odometry.FinalTrajectoryTail()) dense.push_back(s);
    ASSERT_EQ(scan_ends.size(), 10u);
    ASSERT_EQ(last_seen.size(), scan_ends.size());
    // Time order, no duplicates, from the first state to the last, every 5 ms at most.
    ASSERT_FALSE(dense.empty());
    EXPECT_EQ(dense.front().first, scan_ends.front());
    EXPECT_EQ(dense.back().first, scan_ends.back());
    for (size_t i = 1; i < dense.size(); ++i) {
      ASSERT_GT(dense[i].first, dense[i - 1].first);
      EXPECT_LE(dense[i].first - dense[i - 1].first, 5'000'000);
    }
    // At every state's time exactly its final estimate.
    std::map<int64_t, SE3> at;
    for (const auto& [t, T] : dense) at[t] = T;
    for (const auto& [t, T] : last_seen) {
      ASSERT_TRUE(at.count(t)) << t;
      EXPECT_LT((at[t].translation() - T.translation()).norm(), 1e-12) << t;
      EXPECT_LT((at[t].rotation() - T.rotation()).norm(), 1e-12) << t;
    }
    // No step at a scan boundary above 1.5x its neighbours.
    std::vector<io::StampedPose> stamped;
    for (const auto& [t, T] : dense) stamped.push_back({t, T});
    const std::vector<int64_t> inner(scan_ends.begin() + 1, scan_ends.end() - 1);
    EXPECT_LE(testing::MaxBoundaryStepRatio(stamped, inner), 1.5);
  }
}

// With a calibration warm-up replay (the first 0.5 s of a 1 s sequence that starts with both
// calibrations wrong) the replaying pipeline carries on and its segments are the final ones: the
// dense trajectory spans every scan from the first, in time order, without a jump at a boundary.
TEST(FinalTrajectory, ContinuesThroughAWarmupReplay) {
  sim::SimulatedSource source(testing::WrongCalibrationSequence(sim::Regime::kMedium, 1.0, 0.020));
  OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  config.calibration.warmup_replay_s = 0.5;
  lioapp::RunOptions options;
  options.trajectory_rate_hz = 200.0;
  const lioapp::RunSummary run = lioapp::RunOdometry(source, config, options);
  ASSERT_EQ(run.failed, 0) << run.first_failure;
  ASSERT_GT(run.warmup_replayed_scans, 0);
  const auto& dense = run.dense;
  ASSERT_GE(run.trajectory.size(), 4u);
  ASSERT_FALSE(dense.empty());
  EXPECT_EQ(dense.front().t_ns, run.trajectory.front().t_ns);
  EXPECT_EQ(dense.back().t_ns, run.trajectory.back().t_ns);
  for (size_t i = 1; i < dense.size(); ++i) {
    ASSERT_GT(dense[i].t_ns, dense[i - 1].t_ns);
    EXPECT_LE(dense[i].t_ns - dense[i - 1].t_ns, 5'000'000);
  }
  std::vector<int64_t> boundaries;
  for (size_t i = 1; i + 1 < run.trajectory.size(); ++i) {
    boundaries.push_back(run.trajectory[i].t_ns);
  }
  EXPECT_LE(testing::MaxBoundaryStepRatio(dense, boundaries), 1.5);
}

// A stand-in estimator: states at the given times moving at 1 m/s along x, its segments linear.
class LineEstimator final : public Estimator {
 public:
  explicit LineEstimator(std::vector<double> times) : times_(std::move(times)) {}
  void Initialise(const PreparedScan&, const Mat3&, SlidingWindow*) override {}
  void AddState(const PreparedScan&, SlidingWindow*, ScanResult*) override {}
  std::unique_ptr<LidarTerm> MakeLidarTerm(const PreparedScan&, SlidingWindow*) const override {
    return nullptr;
  }
  void MapPoints(const PreparedScan&, std::vector<Vec3>*) const override {}
  void Report(ScanResult*) const override {}
  int num_states() const override { return static_cast<int>(times_.size()); }
  std::vector<StateId> OldestKeys() const override { return {}; }
  std::vector<StateId> NewestKeys() const override { return {}; }
  void DropOldest() override { times_.erase(times_.begin()); }
  double newest_time() const override { return times_.back(); }
  SE3 NewestPose() const override { return At(times_.back()); }
  SE3 PreviousPose() const override { return At(times_.back()); }
  StateId NewestPoseKey() const override { return 0; }
  Mat6 NewestPoseTangentFromBody() const override { return Mat6::Identity(); }
  double previous_time() const override { return times_.front(); }
  std::vector<SE3> PosesSincePrevious(const std::vector<double>& t) const override {
    return UnsealedPoses(t);
  }
  std::string ImuGapRecovery() const override { return ""; }
  std::vector<double> StateTimes() const override { return times_; }
  std::vector<SE3> SealOldest(const std::vector<double>& t) override { return UnsealedPoses(t); }
  std::vector<SE3> UnsealedPoses(const std::vector<double>& t) const override {
    std::vector<SE3> out;
    for (const double x : t) out.push_back(At(x));
    return out;
  }

 private:
  static SE3 At(double t) { return SE3(Mat3::Identity(), Vec3(t, 0.0, 0.0)); }
  std::vector<double> times_;
};

// States every 0.1 s from 0.05 s, the one at 0.35 s a failed scan's: the pieces end at 0.25 s
// and restart at 0.45 s; the grid is the multiples of 20 ms in between, plus each state's time.
TEST(FinalTrajectory, WritesNoSegmentAcrossAFailedScan) {
  LineEstimator estimator({0.05, 0.15, 0.25, 0.35, 0.45, 0.55});
  FinalTrajectory trajectory;
  trajectory.set_rate(50.0);
  trajectory.MarkFailed(0.25, 0.35);
  const int64_t origin = 1'000'000'000;
  FinalTrajectory::Samples samples;
  for (int i = 0; i < 4; ++i) {
    trajectory.SealOldest(&estimator, origin);
    estimator.DropOldest();
  }
  samples = trajectory.Take();
  EXPECT_TRUE(trajectory.Take().empty());  // moved out
  for (const auto& s : trajectory.Tail(estimator, origin)) samples.push_back(s);
  std::vector<int64_t> expected;
  const auto ms = [&](int64_t x) { return origin + x * 1'000'000; };
  expected.push_back(ms(50));
  for (int64_t x = 60; x < 250; x += 20) {
    expected.push_back(ms(x));
    if (x == 140) expected.push_back(ms(150));
  }
  expected.push_back(ms(250));
  expected.push_back(ms(450));
  for (int64_t x = 460; x < 550; x += 20) expected.push_back(ms(x));
  expected.push_back(ms(550));
  std::sort(expected.begin(), expected.end());
  ASSERT_EQ(samples.size(), expected.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i].first, expected[i]) << i;
    EXPECT_NEAR(samples[i].second.translation().x(), 1e-9 * double(expected[i] - origin), 1e-9);
  }
}

}  // namespace
}  // namespace ctlio::lio
