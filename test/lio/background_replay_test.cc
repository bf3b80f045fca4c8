// The warm-up replay on a second thread (calibrating_odometry.h, ReplaySchedule; the worker:
// solvers/src/lio/warmup_replay_worker.h): what it adopts equals the replay inside the scan that
// reached the span, bit for bit, whatever the threads' timing; before the adopting scan the live
// pipeline's results are returned; Finish adopts at the end of the input.
#include <gtest/gtest.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/calibrating_odometry.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

OdometryConfig Calibrating(double warmup_replay_s) {
  OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  config.calibration.warmup_replay_s = warmup_replay_s;
  if (warmup_replay_s > 0.0) config.calibration.warmup_replay_passes = 2;
  config.kept_results = 0;
  return config;
}

// Medium motion, 1.2 s, both calibrations from the wrong start (20 ms, 3° / 10 cm).
sim::SimConfig WrongStart() {
  return testing::WrongCalibrationSequence(sim::Regime::kMedium, 1.2, 0.020);
}

template <class Odometry>
std::vector<ScanResult> Feed(Odometry* odometry) {
  sim::SimulatedSource source(WrongStart());
  std::vector<ScanResult> out;
  io::ScanFrame frame;
  while (source.Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) odometry->AddImu(x);
    out.push_back(odometry->AddScan(lioapp::TakeLidarScan(&frame)));
  }
  return out;
}

int RevisingScan(const std::vector<ScanResult>& results) {
  int at = -1;
  for (size_t i = 0; i < results.size(); ++i) {
    if (results[i].revised_scans > 0) {
      EXPECT_EQ(at, -1) << "a second revising scan: " << i;
      at = static_cast<int>(i);
    }
  }
  return at;
}

void ExpectSameEstimate(const ScanResult& a, const ScanResult& b, size_t i) {
  EXPECT_EQ(a.t_ns, b.t_ns) << i;
  EXPECT_EQ(a.T_mr.Matrix(), b.T_mr.Matrix()) << i;
  EXPECT_EQ(a.calibration.time_offset_s, b.calibration.time_offset_s) << i;
  EXPECT_EQ(a.calibration.T_imu_lidar.Matrix(), b.calibration.T_imu_lidar.Matrix()) << i;
  EXPECT_EQ(a.calibration.time_offset_sigma_s, b.calibration.time_offset_sigma_s) << i;
}

TEST(BackgroundReplay, AdoptsWhatTheReplayInsideTheScanGivesBitForBit) {
  const OdometryConfig config = Calibrating(0.5);
  CalibratingOdometry inside(config);  // ReplaySchedule{}: inside the scan that reached the span
  const std::vector<ScanResult> expected = Feed(&inside);
  const int k = RevisingScan(expected);
  ASSERT_GT(k, 0);
  // The live pipeline alone: what is returned before the adopting scan.
  CalibratingOdometry live(Calibrating(0.0));
  const std::vector<ScanResult> live_results = Feed(&live);

  CalibratingOdometry driver(config, ReplaySchedule{true, 0.25});
  const std::vector<ScanResult> returned = Feed(&driver);
  ASSERT_EQ(returned.size(), expected.size());
  const int s = RevisingScan(returned);
  // Adopted with the first scan ending 0.25 s after scan k's end: 0.1 s sweeps.
  ASSERT_GT(s, k);
  EXPECT_LE(s, k + 3);
  ASSERT_LT(static_cast<size_t>(s), returned.size());
  EXPECT_GE(returned[static_cast<size_t>(s)].t_ns - returned[static_cast<size_t>(k)].t_ns,
            250'000'000);
  EXPECT_LT(returned[static_cast<size_t>(s - 1)].t_ns - returned[static_cast<size_t>(k)].t_ns,
            250'000'000);
  EXPECT_EQ(returned[static_cast<size_t>(s)].revised_scans, s);
  for (size_t i = 0; i < returned.size(); ++i) {
    ExpectSameEstimate(returned[i], static_cast<int>(i) < s ? live_results[i] : expected[i], i);
  }
  // The history after the swap: the replay's for every scan, as inside the scan.
  ASSERT_EQ(driver.results().size(), inside.results().size());
  for (size_t i = 0; i < driver.results().size(); ++i) {
    ExpectSameEstimate(driver.results()[i], inside.results()[i], i);
  }
  ASSERT_EQ(driver.warmup_results().size(), static_cast<size_t>(s) + 1);
  EXPECT_EQ(driver.warmup_results().back().T_mr.Matrix(), live_results[s].T_mr.Matrix());
  EXPECT_EQ(driver.config().T_imu_lidar.Matrix(), inside.config().T_imu_lidar.Matrix());
  EXPECT_EQ(driver.num_marginalizations(), inside.num_marginalizations());
  EXPECT_FALSE(driver.replay_pending());
  EXPECT_FALSE(driver.Finish().has_value());
  // The cost: two passes over scans 0…k, then the catch-up k+1…s.
  ASSERT_TRUE(driver.last_replay().has_value());
  EXPECT_EQ(driver.last_replay()->scans, 2 * (k + 1) + (s - k));
  EXPECT_GT(driver.last_replay()->cpu_ms, 0.0);
  ASSERT_TRUE(inside.last_replay().has_value());
  EXPECT_EQ(inside.last_replay()->scans, 2 * (k + 1));
}

// The input ends before the adopting scan: Finish waits for the catch-up on every scan and
// adopts; the history is then the replay inside the scan's.
TEST(BackgroundReplay, FinishAdoptsAtTheEndOfTheInput) {
  const OdometryConfig config = Calibrating(0.5);
  CalibratingOdometry inside(config);
  Feed(&inside);
  CalibratingOdometry driver(config, ReplaySchedule{true, 100.0});
  const std::vector<ScanResult> returned = Feed(&driver);
  EXPECT_EQ(RevisingScan(returned), -1);
  EXPECT_TRUE(driver.replay_pending());
  const std::optional<ScanResult> last = driver.Finish();
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->revised_scans, static_cast<int>(returned.size()) - 1);
  EXPECT_FALSE(driver.replay_pending());
  ASSERT_EQ(driver.results().size(), inside.results().size());
  for (size_t i = 0; i < driver.results().size(); ++i) {
    ExpectSameEstimate(driver.results()[i], inside.results()[i], i);
  }
  ExpectSameEstimate(*last, inside.results().back(), returned.size() - 1);
  // A pending replay that is never adopted is cancelled when the driver goes.
  auto dropped = std::make_unique<CalibratingOdometry>(config, ReplaySchedule{true, 100.0});
  Feed(dropped.get());
  EXPECT_TRUE(dropped->replay_pending());
  dropped.reset();
}

TEST(BackgroundReplay, RejectsANegativeAdoptionDelay) {
  EXPECT_THROW(CalibratingOdometry(Calibrating(0.5), ReplaySchedule{true, -1.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::lio
