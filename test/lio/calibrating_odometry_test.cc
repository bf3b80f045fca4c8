// The warm-up replay's driver on its own (calibrating_odometry.h): the replay's start config, the
// frozen report, the forwarding to the single-pass pipeline, the swap at the span and the giving
// up after twice the span; and its alternative, forgetting the warm-up's calibration information
// at the span. The replay's effect on the calibration: warmup_replay_test.cc.
#include "ctlio/solvers/lio/calibrating_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

OdometryConfig Calibrating(double warmup_replay_s) {
  OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  config.calibration.warmup_replay_s = warmup_replay_s;
  return config;
}

// Medium motion, 1 s, both calibrations from the wrong start (20 ms, 3° / 10 cm).
sim::SimConfig WrongStart() {
  return testing::WrongCalibrationSequence(sim::Regime::kMedium, 1.0, 0.020);
}

// Feeds every frame of `config`'s sequence to `odometry`; the results AddScan returned, and in
// *pipelines (if given) which pipeline each scan was processed by (CalibratingOdometry only).
template <class Odometry>
std::vector<ScanResult> Feed(const sim::SimConfig& config, Odometry* odometry,
                             std::vector<const void*>* pipelines = nullptr) {
  sim::SimulatedSource source(config);
  std::vector<ScanResult> out;
  io::ScanFrame frame;
  while (source.Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) odometry->AddImu(x);
    out.push_back(odometry->AddScan(lioapp::TakeLidarScan(&frame)));
    if constexpr (std::is_same_v<Odometry, CalibratingOdometry>) {
      if (pipelines != nullptr) pipelines->push_back(&odometry->pipeline());
    }
  }
  return out;
}

ScanResult::CalibrationEstimate Estimate(const OdometryConfig& config, const Vec6& xi) {
  ScanResult::CalibrationEstimate e;
  e.time_offset_s = {0.020};
  e.time_offset_sigma_s = {0.001};
  e.has_extrinsic = true;
  e.T_imu_lidar = SE3::Exp(xi) * config.T_imu_lidar;
  e.extrinsic_sigma = Vec6::Constant(0.01);
  return e;
}

TEST(ReplayConfig, StartsFromTheObservableEstimatesAndTheConfigElsewhere) {
  OdometryConfig config = Calibrating(2.0);
  config.calibration.time_offset_s = {0.005};
  config.calibration.warmup_replay_passes = 3;
  config.calibration.warmup_replay_hold = true;
  config.T_imu_lidar = SE3(Mat3::Identity(), Vec3(0.1, 0.0, 0.0));
  const Vec6 xi = (Vec6() << 0.01, -0.02, 0.03, 0.004, -0.005, 0.006).finished();
  ScanResult::CalibrationEstimate estimate = Estimate(config, xi);
  estimate.unobservable = {false, true, false, false, false, false, true};  // ρ_x, φ_z
  const OdometryConfig replay = ReplayConfig(config, estimate);
  // No replay of its own, a valid config.
  EXPECT_EQ(replay.calibration.warmup_replay_s, 0.0);
  EXPECT_EQ(replay.calibration.warmup_replay_passes, 1);
  EXPECT_FALSE(replay.calibration.warmup_replay_hold);
  EXPECT_NO_THROW(replay.Validate());
  EXPECT_EQ(replay.calibration.TimeOffset(0), 0.020);
  // The prior σ stays the configured one.
  EXPECT_EQ(replay.calibration.time_offset_prior_sigma_s,
            config.calibration.time_offset_prior_sigma_s);
  EXPECT_EQ(replay.calibration.extrinsic_prior_sigma_m, config.calibration.extrinsic_prior_sigma_m);
  const Vec6 start = (replay.T_imu_lidar * config.T_imu_lidar.Inverse()).Log();
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(start[k], (k == 0 || k == 5) ? 0.0 : xi[k], 1e-12) << k;
  }
  // An unobservable offset starts from the configured value; without a check (no mask) every
  // coordinate starts from the estimate.
  estimate.unobservable[0] = true;
  EXPECT_EQ(ReplayConfig(config, estimate).calibration.TimeOffset(0), 0.005);
  estimate.unobservable.clear();
  const OdometryConfig unchecked = ReplayConfig(config, estimate);
  EXPECT_LT(((unchecked.T_imu_lidar * config.T_imu_lidar.Inverse()).Log() - xi).norm(), 1e-12);
}

TEST(FrozenCalibration, ReportsTheValuesRunWithTheEstimatesSigmaAllHeld) {
  OdometryConfig config = Calibrating(2.0);
  const Vec6 xi = (Vec6() << 0.01, -0.02, 0.03, 0.004, -0.005, 0.006).finished();
  ScanResult::CalibrationEstimate estimate = Estimate(config, xi);
  estimate.unobservable = {false, false, false, false, false, false, true};
  OdometryConfig run = ReplayConfig(config, estimate);
  const ScanResult::CalibrationEstimate frozen = FrozenCalibration(estimate, run);
  EXPECT_EQ(frozen.time_offset_s, std::vector<double>{0.020});
  EXPECT_EQ(frozen.T_imu_lidar.Matrix(), run.T_imu_lidar.Matrix());  // φ_z back at the config
  EXPECT_NE(frozen.T_imu_lidar.Matrix(), estimate.T_imu_lidar.Matrix());
  EXPECT_EQ(frozen.time_offset_sigma_s, estimate.time_offset_sigma_s);
  EXPECT_EQ(frozen.extrinsic_sigma, estimate.extrinsic_sigma);
  EXPECT_EQ(frozen.unobservable, estimate.unobservable);
  EXPECT_EQ(frozen.held, std::vector<bool>(7, true));
}

// The single-pass pipeline refuses a replay (it would silently not run it); the driver takes it.
TEST(CalibratingOdometry, OnlyTheDriverTakesAReplay) {
  try {
    LioOdometry odometry(Calibrating(1.0));
    FAIL() << "LioOdometry accepted calibration.warmup_replay_s";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CalibratingOdometry"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(LioOdometry{Calibrating(0.0)});
  CalibratingOdometry odometry(Calibrating(1.0));
  EXPECT_TRUE(odometry.keeps_warmup());
  EXPECT_EQ(odometry.config().calibration.warmup_replay_s, 1.0);  // the caller's config
  EXPECT_EQ(odometry.pipeline().config().calibration.warmup_replay_s, 0.0);
  OdometryConfig bad = Calibrating(1.0);
  bad.calibration.warmup_replay_passes = 0;
  EXPECT_THROW(CalibratingOdometry{bad}, std::invalid_argument);
  // Nothing to calibrate: nothing kept.
  OdometryConfig known = Calibrating(1.0);
  known.calibration.estimate_time_offset = false;
  known.calibration.estimate_extrinsic = false;
  EXPECT_FALSE(CalibratingOdometry(known).keeps_warmup());
}

// Without a replay the driver only forwards: the single pipeline's results, bit for bit.
TEST(CalibratingOdometry, WithoutAReplayItIsTheSinglePass) {
  OdometryConfig config = Calibrating(0.0);
  config.kept_results = 0;
  CalibratingOdometry driver(config);
  LioOdometry single(config);
  std::vector<const void*> pipelines;
  const std::vector<ScanResult> a = Feed(WrongStart(), &driver, &pipelines);
  const std::vector<ScanResult> b = Feed(WrongStart(), &single);
  ASSERT_GE(a.size(), 9u);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(driver.results().size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].T_mr.Matrix(), b[i].T_mr.Matrix()) << i;
    EXPECT_EQ(a[i].calibration.time_offset_s, b[i].calibration.time_offset_s) << i;
    EXPECT_EQ(driver.results()[i].t_ns, a[i].t_ns) << i;
    EXPECT_EQ(pipelines[i], pipelines.front()) << i;
  }
  EXPECT_TRUE(driver.warmup_results().empty());
  EXPECT_EQ(driver.num_marginalizations(), single.num_marginalizations());
}

// At the first estimated scan past the span the driver swaps in a fresh pipeline that has
// processed the kept span from ReplayConfig(the live estimate): every result from then on, and
// the span's in results(), are those of that single pass over the whole sequence.
TEST(CalibratingOdometry, SwapsInTheReplayedPipelineAtTheSpan) {
  OdometryConfig config = Calibrating(0.5);
  config.kept_results = 0;
  CalibratingOdometry driver(config);
  std::vector<const void*> pipelines;
  const std::vector<ScanResult> returned = Feed(WrongStart(), &driver, &pipelines);
  int swapped_at = -1, swaps = 0;
  for (size_t i = 1; i < pipelines.size(); ++i) {
    if (pipelines[i] != pipelines[i - 1]) {
      swapped_at = static_cast<int>(i);
      ++swaps;
    }
  }
  ASSERT_EQ(swaps, 1);
  ASSERT_EQ(returned[static_cast<size_t>(swapped_at)].revised_scans, swapped_at);
  for (size_t i = 0; i < returned.size(); ++i) {
    EXPECT_EQ(returned[i].revised_scans > 0, static_cast<int>(i) == swapped_at) << i;
  }
  EXPECT_FALSE(driver.keeps_warmup());
  ASSERT_EQ(driver.warmup_results().size(), static_cast<size_t>(swapped_at) + 1);
  // The live results of the span are what AddScan returned then.
  for (int i = 0; i < swapped_at; ++i) {
    EXPECT_EQ(driver.warmup_results()[static_cast<size_t>(i)].T_mr.Matrix(),
              returned[static_cast<size_t>(i)].T_mr.Matrix());
  }
  // The reference: one pass from the live estimate after the swapping scan.
  const OdometryConfig replay_config =
      ReplayConfig(config, driver.warmup_results().back().calibration);
  EXPECT_EQ(driver.config().T_imu_lidar.Matrix(), replay_config.T_imu_lidar.Matrix());
  EXPECT_EQ(driver.config().calibration.time_offset_s, replay_config.calibration.time_offset_s);
  LioOdometry reference(replay_config);
  const std::vector<ScanResult> expected = Feed(WrongStart(), &reference);
  ASSERT_EQ(driver.results().size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_LT((driver.results()[i].T_mr.Matrix() - expected[i].T_mr.Matrix()).norm(), 1e-9) << i;
    if (static_cast<int>(i) >= swapped_at) {
      EXPECT_LT((returned[i].T_mr.Matrix() - expected[i].T_mr.Matrix()).norm(), 1e-9) << i;
    }
  }
  EXPECT_EQ(driver.num_marginalizations(), reference.num_marginalizations());
}

// Scans without any IMU sample never initialise: the driver waits for an estimated scan until
// twice the span has passed, then drops the kept data with a note, and the result history is
// bounded again from the next scan on.
TEST(CalibratingOdometry, GivesUpAfterTwiceTheSpanWithoutAnEstimate) {
  OdometryConfig config = Calibrating(0.22);
  config.kept_results = 2;
  CalibratingOdometry driver(config);
  const int64_t period = 100'000'000;  // 0.1 s sweeps
  for (int k = 0; k < 7; ++k) {
    LidarScan scan;
    scan.begin_ns = 1'000'000'000 + k * period;
    scan.end_ns = scan.begin_ns + period;
    for (int j = 0; j < 200; ++j) {
      scan.points.emplace_back(5.0, 0.01 * j - 1.0, 0.5 * std::sin(0.1 * j));
      scan.times_ns.push_back(scan.begin_ns + j * (period / 200));
    }
    const ScanResult r = driver.AddScan(scan);
    ASSERT_EQ(r.status, ScanStatus::kFailed) << "scan " << k;
    const bool gave_up = r.message.find("calibration warm-up not replayed") != std::string::npos;
    // Span 0.1 (k + 1) s: the first scan past 2 × 0.22 s is k = 4.
    EXPECT_EQ(gave_up, k == 4) << "scan " << k << ": " << r.message;
    EXPECT_EQ(driver.keeps_warmup(), k < 4) << "scan " << k;
    EXPECT_EQ(driver.results().size(), k <= 4 ? static_cast<size_t>(k + 1) : 2u) << "scan " << k;
    EXPECT_EQ(r.revised_scans, 0);
  }
  EXPECT_TRUE(driver.warmup_results().empty());
  EXPECT_EQ(driver.config().calibration.warmup_replay_s, 0.22);  // the live pipeline carries on
}

// calibration.warmup_forget_s: at the first estimated scan ending 0.5 s after the first began,
// the marginal prior forgets the calibration (once, with a note); until then the run is the run
// without it bit for bit, and after it the calibration's σ is larger (the warm-up's information
// is gone) while the pose covariance still reads the window's (new) marginal prior.
TEST(CalibratingOdometry, ForgetsTheWarmupsCalibrationInformationOnceAtTheSpan) {
  OdometryConfig config = Calibrating(0.0);
  config.kept_results = 0;
  config.pose_covariance = true;
  OdometryConfig forgetting = config;
  forgetting.calibration.warmup_forget_s = 0.5;
  EXPECT_THROW(LioOdometry{forgetting}, std::invalid_argument);  // the driver's option
  OdometryConfig both = forgetting;
  both.calibration.warmup_replay_s = 1.0;
  EXPECT_THROW(both.Validate(), std::invalid_argument);
  OdometryConfig negative = config;
  negative.calibration.warmup_forget_s = -1.0;
  EXPECT_THROW(negative.Validate(), std::invalid_argument);

  CalibratingOdometry plain(config), driver(forgetting);
  const std::vector<ScanResult> a = Feed(WrongStart(), &plain);
  const std::vector<ScanResult> b = Feed(WrongStart(), &driver);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(b.size(), 9u);
  int forgot_at = -1, notes = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    if (b[i].message.find("calibration warm-up forgotten") != std::string::npos) {
      forgot_at = static_cast<int>(i);
      ++notes;
    }
  }
  ASSERT_EQ(notes, 1);
  // 0.1 s sweeps from the first scan's begin: the fifth scan ends at 0.5 s, or a hair before it
  // (the sweep's last firing), and then the sixth.
  EXPECT_GE(forgot_at, 4);
  EXPECT_LE(forgot_at, 5);
  EXPECT_NE(driver.results()[static_cast<size_t>(forgot_at)].message.find("forgotten"),
            std::string::npos);
  for (int i = 0; i <= forgot_at; ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_EQ(a[k].T_mr.Matrix(), b[k].T_mr.Matrix()) << i;
    EXPECT_EQ(a[k].calibration.time_offset_s, b[k].calibration.time_offset_s) << i;
  }
  const size_t next = static_cast<size_t>(forgot_at) + 1;
  ASSERT_EQ(b[next].calibration.time_offset_sigma_s.size(), 1u);
  EXPECT_GT(b[next].calibration.time_offset_sigma_s[0], a[next].calibration.time_offset_sigma_s[0]);
  EXPECT_GT(b[next].calibration.extrinsic_sigma.head<3>().norm(),
            a[next].calibration.extrinsic_sigma.head<3>().norm());
  for (size_t i = next; i < b.size(); ++i) {
    ASSERT_NE(b[i].status, ScanStatus::kFailed) << i << ": " << b[i].message;
    EXPECT_TRUE(b[i].has_pose_covariance) << i;
    EXPECT_TRUE(b[i].pose_covariance.allFinite()) << i;
  }
  // With the map restarted from the forgetting scan: said in the note, and the run goes on.
  OdometryConfig restarting = forgetting;
  restarting.calibration.warmup_forget_restart_map = true;
  CalibratingOdometry restarted(restarting);
  const std::vector<ScanResult> c = Feed(WrongStart(), &restarted);
  ASSERT_EQ(c.size(), b.size());
  EXPECT_NE(c[static_cast<size_t>(forgot_at)].message.find("the map restarted"), std::string::npos);
  for (size_t i = next; i < c.size(); ++i) {
    ASSERT_NE(c[i].status, ScanStatus::kFailed) << i << ": " << c[i].message;
  }
  OdometryConfig restart_alone = config;
  restart_alone.calibration.warmup_forget_restart_map = true;
  EXPECT_THROW(restart_alone.Validate(), std::invalid_argument);
  // Nothing to calibrate: nothing forgotten.
  OdometryConfig known = forgetting;
  known.calibration.estimate_time_offset = false;
  known.calibration.estimate_extrinsic = false;
  CalibratingOdometry uncalibrated(known);
  for (const ScanResult& r : Feed(WrongStart(), &uncalibrated)) {
    EXPECT_EQ(r.message.find("forgotten"), std::string::npos) << r.message;
  }
}

}  // namespace
}  // namespace ctlio::lio
