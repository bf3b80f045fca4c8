// The keypoint budget that follows the motion (sweep_keypoint_budget.h,
// window.slow_sweep_max_keypoints / window.slow_sweep_speed): the cap it picks for a split, a slow
// and a fast sweep around its threshold, the keys' checks, and the pipeline: a walk below the
// threshold registers the slow budget, a threshold below the walk's estimated speed leaves its
// sweeps (once moving) the front end's keypoints, and the key off is the run without it bit for
// bit.
#include "ctlio/solvers/lio/sweep_keypoint_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

SlowSweepKeypoints Slow(int max_keypoints, double speed) {
  SlowSweepKeypoints s;
  s.max_keypoints = max_keypoints;
  s.speed = speed;
  return s;
}

TEST(SweepKeypointBudget, SlowUnsplitSweepsGetTheSlowBudgetStrictlyBelowTheThreshold) {
  AdaptiveKnotOptions adaptive;
  adaptive.max_keypoints = 300;
  const SlowSweepKeypoints slow = Slow(1200, 4.0);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, 0.0), 1200);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, 1.4), 1200);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, 3.999), 1200);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, 4.0), 0);  // at the threshold: not slow
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, 11.0), 0);
  // A diverged estimate is not slow.
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, false, std::numeric_limits<double>::infinity()), 0);
  // A split sweep has the split budget whatever its speed, also when that is the front end's (0).
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, true, 1.4), 300);
  EXPECT_EQ(SweepKeypointCap(adaptive, slow, true, 11.0), 300);
  EXPECT_EQ(SweepKeypointCap(AdaptiveKnotOptions(), slow, true, 1.4), 0);
  // Off (the default): the front end's keypoints on every unsplit sweep.
  EXPECT_FALSE(SlowSweepKeypoints().enabled());
  for (const double v : {0.0, 1.4, 11.0}) {
    EXPECT_EQ(SweepKeypointCap(adaptive, SlowSweepKeypoints(), false, v), 0) << v;
    EXPECT_EQ(SweepKeypointCap(adaptive, Slow(0, 100.0), false, v), 0) << v;
  }
}

TEST(SweepKeypointBudget, KeysAreReadAndChecked) {
  const std::string path = ::testing::TempDir() + "/slow_sweep_keypoints.yaml";
  std::ofstream(path) << "window:\n  slow_sweep_max_keypoints: 1200\n  slow_sweep_speed: 3.5\n";
  const OdometryConfig c = LoadOdometryConfig(path);
  EXPECT_EQ(c.slow_sweep_keypoints.max_keypoints, 1200);
  EXPECT_EQ(c.slow_sweep_keypoints.speed, 3.5);
  EXPECT_EQ(OdometryConfig().slow_sweep_keypoints.max_keypoints, 0);  // off in code
  for (const std::string& bad :
       {std::string("slow_sweep_max_keypoints: -5"), std::string("slow_sweep_speed: 0"),
        std::string("slow_sweep_speed: -1"), std::string("slow_sweep_speed: .nan")}) {
    std::ofstream(path) << "window:\n  " << bad << "\n";
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(bad.substr(0, bad.find(':'))), std::string::npos) << what;
      EXPECT_NE(what.find("slow_sweep_keypoints.yaml"), std::string::npos) << what;
    }
  }
  OdometryConfig v;
  v.slow_sweep_keypoints = Slow(1000001, 4.0);
  EXPECT_THROW(v.Validate(), std::invalid_argument);
  v.slow_sweep_keypoints = Slow(1200, std::numeric_limits<double>::infinity());
  EXPECT_THROW(v.Validate(), std::invalid_argument);
  v.slow_sweep_keypoints = Slow(1200, 4.0);
  EXPECT_NO_THROW(v.Validate());
}

std::vector<ScanResult> RunWalk(const OdometryConfig& config) {
  sim::SimulatedSource source(testing::ShortSequenceAtIndex100(sim::Regime::kWalking));
  auto odometry = MakeLioOdometry(config);
  io::ScanFrame f;
  std::vector<ScanResult> scans;
  while (source.Next(&f)) {
    for (const auto& x : f.imu) odometry->AddImu(x);
    scans.push_back(odometry->AddScan(lioapp::TakeLidarScan(&f)));
  }
  return scans;
}

// A 1.5 s walk (index 100, 16 beams, 1.2–1.6 m/s after a 1 s start ramp) with the front end's cap
// at 40 keypoints, below what its sweeps offer.
TEST(SweepKeypointBudget, AWalkBelowTheThresholdRegistersTheSlowBudget) {
  OdometryConfig base = testing::SimLioConfig();
  base.frontend.max_keypoints = 40;
  const std::vector<ScanResult> capped = RunWalk(base);
  ASSERT_GE(capped.size(), 10u);

  // Off, whatever the threshold: the run without the key, bit for bit.
  OdometryConfig off = base;
  off.slow_sweep_keypoints = Slow(0, 0.01);
  const std::vector<ScanResult> unchanged = RunWalk(off);
  ASSERT_EQ(unchanged.size(), capped.size());
  for (size_t i = 0; i < capped.size(); ++i) {
    EXPECT_EQ(unchanged[i].keypoints, capped[i].keypoints) << "scan " << i;
    EXPECT_EQ(unchanged[i].T_mr.Matrix(), capped[i].T_mr.Matrix()) << "scan " << i;
  }

  // Every sweep of the walk is slow at 4 m/s: up to 120 keypoints, more than the front end's 40.
  OdometryConfig walking = base;
  walking.slow_sweep_keypoints = Slow(120, 4.0);
  const std::vector<ScanResult> slow = RunWalk(walking);
  ASSERT_EQ(slow.size(), capped.size());
  int above = 0;
  for (size_t i = 1; i < slow.size(); ++i) {
    ASSERT_NE(slow[i].status, ScanStatus::kFailed) << "scan " << i;
    EXPECT_LE(capped[i].keypoints, 40) << "scan " << i;
    EXPECT_LE(slow[i].keypoints, 120) << "scan " << i;
    if (slow[i].keypoints > 40) ++above;
  }
  EXPECT_GE(above, static_cast<int>(slow.size()) - 2);

  // A threshold of 0.3 m/s: the first sweep starts from the knot at rest (slow), the sweeps of the
  // last half second, at walking speed, are not slow and keep the front end's 40.
  OdometryConfig low = base;
  low.slow_sweep_keypoints = Slow(120, 0.3);
  const std::vector<ScanResult> moving = RunWalk(low);
  ASSERT_EQ(moving.size(), capped.size());
  EXPECT_GT(moving[1].keypoints, 40);
  for (size_t i = moving.size() - 5; i < moving.size(); ++i) {
    ASSERT_NE(moving[i].status, ScanStatus::kFailed) << "scan " << i;
    EXPECT_LE(moving[i].keypoints, 40) << "scan " << i;
  }
}

}  // namespace
}  // namespace ctlio::lio
