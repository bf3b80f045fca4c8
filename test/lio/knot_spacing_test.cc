// The knot spacing chosen from the motion (knot_spacing.h, window.adaptive_knots_*): the line
// residual it measures, the knot count it picks at and around its thresholds, a handheld 6 Hz
// rotation against a walk, and the pipeline with a knot count that changes from sweep to sweep:
// every sweep gets the count the rule gives for its own IMU samples, exactly that many knots are
// marginalised after it, every IMU sample is measured once, and a run the rule never triggers in
// is the fixed-count run bit for bit; a split sweep's own keypoint budget.
#include "ctlio/solvers/lio/knot_spacing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "common/sim_lio.h"
#include "common/test_paths.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 0.1 s sweep of a 400 Hz IMU: the sample times and ω(t) from `rate`.
template <typename Rate>
void Sweep(Rate rate, std::vector<double>* t, std::vector<Vec3>* gyro) {
  t->clear();
  gyro->clear();
  for (int i = 1; i <= 40; ++i) {
    t->push_back(0.0025 * i);
    gyro->push_back(rate(t->back()));
  }
}

TEST(KnotSpacing, LineResidualIsZeroForALineAndCT2OverRoot180ForAParabola) {
  std::vector<double> t;
  std::vector<Vec3> x;
  Sweep([](double s) -> Vec3 { return Vec3(0.3 + 2.0 * s, -1.0 - 5.0 * s, 0.01); }, &t, &x);
  EXPECT_LT(LineResidualRms(t, x), 1e-12);
  // c·t² on one axis: the residual about its line over n samples h apart is
  // |c|·h²·√((n²−1)(n²−4)/180), which tends to |c|·T²/√180 over [0, T] (the quadratic Legendre
  // component).
  const double c = 300.0;
  Sweep([c](double s) -> Vec3 { return Vec3(0.0, c * s * s, 1.0); }, &t, &x);
  const double n = static_cast<double>(t.size()), h = t[1] - t[0];
  EXPECT_NEAR(LineResidualRms(t, x), c * h * h * std::sqrt((n * n - 1) * (n * n - 4) / 180.0),
              1e-9);
  const double T = t.back() - t.front();
  EXPECT_NEAR(LineResidualRms(t, x), c * T * T / std::sqrt(180.0), 0.06 * c * T * T);
  // Too few samples to tell a curve from a line.
  EXPECT_EQ(LineResidualRms({0.0, 0.1}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}), 0.0);
  EXPECT_EQ(LineResidualRms({0.1, 0.1, 0.1}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}), 0.0);
}

AdaptiveKnotOptions Options(int max, double gyro, double accel = 0.0) {
  AdaptiveKnotOptions o;
  o.max_knots_per_scan = max;
  o.gyro_curvature = gyro;
  o.accel_curvature = accel;
  return o;
}

TEST(KnotSpacing, AHandheldSixHertzRotationGetsTwoKnotsAWalkOne) {
  std::vector<double> t;
  std::vector<Vec3> gyro;
  const std::vector<Vec3> accel(40, Vec3(0.0, 0.0, 9.81));
  // Handheld fast (the fast regime): 1.5 rad/s at 6 Hz about a tilted axis, plus a bias.
  Sweep(
      [](double s) -> Vec3 {
        return Vec3(0.01, 0.6, 0.8) * 1.5 * std::sin(2.0 * kPi * 6.0 * s + 0.4) +
               Vec3(0.002, -0.003, 0.001);
      },
      &t, &gyro);
  const double fast = LineResidualRms(t, gyro);
  EXPECT_NEAR(fast, 0.466, 0.01);  // the residual of the sine about its line over 0.1 s
  EXPECT_EQ(KnotsForSweep(Options(2, 0.15), 1, t, gyro, accel), 2);
  // Up to 3 allowed: r / 4 ≤ 0.15 already with two, so two.
  EXPECT_EQ(KnotsForSweep(Options(3, 0.15), 1, t, gyro, accel), 2);
  EXPECT_EQ(KnotsForSweep(Options(3, 0.1), 1, t, gyro, accel), 3);  // r / 4 > 0.1
  // A walk: the 2 Hz gait and a head turn, 0.3 rad/s, with the gyro noise of a MEMS unit.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  Sweep(
      [&](double s) -> Vec3 {
        return Vec3(0.3 * std::sin(2.0 * kPi * 2.0 * s), 0.1 * std::cos(2.0 * kPi * 2.0 * s), 0.4) +
               Vec3(noise(rng), noise(rng), noise(rng));
      },
      &t, &gyro);
  EXPECT_LT(LineResidualRms(t, gyro), 0.05);
  EXPECT_EQ(KnotsForSweep(Options(2, 0.15), 1, t, gyro, accel), 1);
  EXPECT_EQ(KnotsForSweep(Options(3, 0.15), 1, t, gyro, accel), 1);
}

TEST(KnotSpacing, FewestKnotsWithResidualOverKSquaredAtMostTheThreshold) {
  // A parabola on one axis, so the residual r is known; thresholds placed around r / K².
  std::vector<double> t;
  std::vector<Vec3> gyro;
  Sweep([](double s) -> Vec3 { return Vec3(100.0 * s * s, 0.0, 0.0); }, &t, &gyro);
  const std::vector<Vec3> accel(t.size(), Vec3::Zero());
  const double r = LineResidualRms(t, gyro);
  ASSERT_GT(r, 0.0);
  const auto knots = [&](int max, double threshold) {
    return KnotsForSweep(Options(max, threshold), 1, t, gyro, accel);
  };
  EXPECT_EQ(knots(5, r * 1.001), 1);
  EXPECT_EQ(knots(5, r * 0.999), 2);
  EXPECT_EQ(knots(5, r / 4.0 * 1.001), 2);
  EXPECT_EQ(knots(5, r / 4.0 * 0.999), 3);
  EXPECT_EQ(knots(5, r / 9.0 * 1.001), 3);
  EXPECT_EQ(knots(5, r / 9.0 * 0.999), 4);
  EXPECT_EQ(knots(2, r / 100.0), 2);  // capped
  // The fixed count is the floor: with 2 fixed a gentle sweep keeps 2, a curved one gets 3.
  EXPECT_EQ(KnotsForSweep(Options(3, r * 2.0), 2, t, gyro, accel), 2);
  EXPECT_EQ(KnotsForSweep(Options(3, r / 6.0), 2, t, gyro, accel), 3);
  // Off: a maximum not above the fixed count, or no threshold; too few samples to measure.
  EXPECT_EQ(KnotsForSweep(Options(1, r / 100.0), 1, t, gyro, accel), 1);
  EXPECT_EQ(KnotsForSweep(Options(2, r / 100.0), 2, t, gyro, accel), 2);
  EXPECT_EQ(KnotsForSweep(Options(3, 0.0), 1, t, gyro, accel), 1);
  EXPECT_EQ(
      KnotsForSweep(Options(3, r / 100.0), 1, {0.0, 0.1}, {gyro[0], gyro[1]}, {accel[0], accel[1]}),
      1);
}

TEST(KnotSpacing, TheAccelerometerThresholdAloneCanAskForKnots) {
  std::vector<double> t;
  std::vector<Vec3> accel;
  Sweep([](double s) -> Vec3 { return Vec3(0.0, 0.0, 9.81 + 2.0 * std::sin(2.0 * kPi * 6.0 * s)); },
        &t, &accel);
  const std::vector<Vec3> gyro(t.size(), Vec3(0.0, 0.0, 0.1));
  const double r = LineResidualRms(t, accel);
  EXPECT_GT(r, 0.3);
  EXPECT_EQ(KnotsForSweep(Options(2, 0.15, 0.0), 1, t, gyro, accel), 1);  // the gyro is a line
  EXPECT_EQ(KnotsForSweep(Options(2, 0.15, r * 0.9), 1, t, gyro, accel), 2);
  EXPECT_EQ(KnotsForSweep(Options(2, 0.15, r * 1.1), 1, t, gyro, accel), 1);
}

TEST(KnotSpacing, ValidateRejectsBadValues) {
  OdometryConfig c;
  EXPECT_FALSE(c.adaptive_knots.enabled(c.knots_per_scan));  // off in code
  c.adaptive_knots = Options(2, 0.15);
  EXPECT_NO_THROW(c.Validate());
  c.adaptive_knots.gyro_curvature = -1.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.adaptive_knots = Options(11, 0.15);
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.adaptive_knots = Options(2, 0.15, std::nan(""));
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

// The YAML keys reach the options; the shipped sensor configs carry the rule (base.yaml), and
// data/sim_lio.yaml (Table II) does not; a bad value names its key.
TEST(KnotSpacing, YamlKeysAndTheShippedDefaults) {
  const std::string path = ::testing::TempDir() + "/adaptive_knots.yaml";
  std::ofstream(path) << "window:\n  adaptive_knots_max: 3\n  adaptive_knots_gyro_curvature: 0.2\n"
                         "  adaptive_knots_accel_curvature: 1.5\n"
                         "  adaptive_knots_accel_variance: 0.3\n"
                         "  adaptive_knots_gyro_variance: 0.001\n";
  const AdaptiveKnotOptions o = LoadOdometryConfig(path).adaptive_knots;
  EXPECT_EQ(o.max_knots_per_scan, 3);
  EXPECT_EQ(o.gyro_curvature, 0.2);
  EXPECT_EQ(o.accel_curvature, 1.5);
  EXPECT_EQ(o.accel_variance_floor, 0.3);
  EXPECT_EQ(o.gyro_variance_floor, 0.001);
  const std::string data = ctlio::testing::SourceDir() + "/data/";
  for (const char* sensor : {"vlp16", "hdl32e", "os1_64", "mid360"}) {
    const OdometryConfig c = LoadOdometryConfig(data + "sensors/" + sensor + ".yaml");
    EXPECT_TRUE(c.adaptive_knots.enabled(c.knots_per_scan)) << sensor;
    EXPECT_EQ(c.adaptive_knots.max_knots_per_scan, 2) << sensor;
    EXPECT_EQ(c.adaptive_knots.gyro_curvature, 0.15) << sensor;
  }
  const OdometryConfig table2 = LoadOdometryConfig(data + "sim_lio.yaml");
  EXPECT_FALSE(table2.adaptive_knots.enabled(table2.knots_per_scan));
  std::ofstream(path) << "window:\n  adaptive_knots_gyro_curvature: -0.1\n";
  try {
    LoadOdometryConfig(path);
    ADD_FAILURE() << "a negative threshold was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("adaptive_knots_gyro_curvature"), std::string::npos)
        << e.what();
  }
}

struct PipelineRun {
  std::vector<ScanResult> scans;
  std::vector<int> marginalized;  // knots that left the window while each scan was processed
  std::vector<double> residual;   // the gyro line residual of each scan's sweep (IMU 0)
  std::vector<int> expected;      // the knot count the rule gives that sweep
  int window_states = 0;
};

PipelineRun RunPipeline(const OdometryConfig& config, sim::Regime regime) {
  sim::SimulatedSource source(testing::ShortSequenceAtIndex100(regime));
  auto odometry = MakeLioOdometry(config);
  io::ScanFrame f;
  PipelineRun run;
  std::vector<ImuSample> imu;
  int64_t previous_end = 0;
  while (source.Next(&f)) {
    for (const auto& x : f.imu) {
      odometry->AddImu(x);
      imu.push_back(x);
    }
    const int before = odometry->num_marginalizations();
    run.scans.push_back(odometry->AddScan(lioapp::TakeLidarScan(&f)));
    run.marginalized.push_back(odometry->num_marginalizations() - before);
    // The sweep (previous scan end, this scan end] as the estimator takes it.
    const int64_t end = run.scans.back().t_ns;
    std::vector<double> t;
    std::vector<Vec3> gyro, accel;
    for (const ImuSample& s : imu) {
      if (s.imu == 0 && s.t_ns > previous_end && s.t_ns <= end) {
        t.push_back(1e-9 * static_cast<double>(s.t_ns - previous_end));
        gyro.push_back(s.gyro);
        accel.push_back(s.accel);
      }
    }
    run.residual.push_back(LineResidualRms(t, gyro));
    run.expected.push_back(
        KnotsForSweep(config.adaptive_knots, config.knots_per_scan, t, gyro, accel));
    previous_end = end;
  }
  run.window_states = odometry->window().num_states();
  return run;
}

TEST(KnotSpacing, PipelineGivesEachSweepItsOwnCountAndMarginalisesExactlyThose) {
  const OdometryConfig one = testing::SimLioConfig();
  const PipelineRun fixed = RunPipeline(one, sim::Regime::kFast);
  // A threshold at the median of this sequence's sweep residuals, so that the count changes
  // from sweep to sweep (both 1 and 2 occur).
  std::vector<double> r(fixed.residual.begin() + 1, fixed.residual.end());
  std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
  OdometryConfig adaptive = one;
  adaptive.adaptive_knots = Options(2, r[r.size() / 2]);
  const PipelineRun run = RunPipeline(adaptive, sim::Regime::kFast);
  ASSERT_EQ(run.scans.size(), 15u);
  ASSERT_EQ(run.scans.size(), fixed.scans.size());
  int ones = 0, twos = 0;
  for (size_t i = 1; i < run.scans.size(); ++i) {
    ASSERT_NE(run.scans[i].status, ScanStatus::kFailed) << "scan " << i;
    // Each IMU sample once, however the sweep is split.
    EXPECT_EQ(run.scans[i].imu_residuals, fixed.scans[i].imu_residuals) << "scan " << i;
    (run.expected[i] == 1 ? ones : twos) += 1;
  }
  EXPECT_GE(ones, 3);
  EXPECT_GE(twos, 3);
  // The window slides before each scan (from the second processed one on) down to one held
  // knot: what leaves is exactly the knots the previous sweep added.
  for (size_t i = 2; i < run.scans.size(); ++i) {
    EXPECT_EQ(run.marginalized[i], run.expected[i - 1]) << "scan " << i;
  }
  // After the last scan: the held knot and the last sweep's knots, four blocks each (pose, ϖ,
  // ϖ̇, bias), as with the fixed count plus the extra knots.
  EXPECT_EQ(run.window_states, fixed.window_states + 4 * (run.expected.back() - 1));
}

TEST(KnotSpacing, ARunTheRuleNeverTriggersInIsTheFixedCountRunBitForBit) {
  const OdometryConfig one = testing::SimLioConfig();
  const PipelineRun fixed = RunPipeline(one, sim::Regime::kWalking);
  OdometryConfig adaptive = one;
  adaptive.adaptive_knots = Options(3, 0.15);
  // Variance floors far above the configured variances: they act on split sweeps only.
  adaptive.adaptive_knots.accel_variance_floor = 100.0 * one.AccelVariance(0);
  adaptive.adaptive_knots.gyro_variance_floor = 100.0 * one.GyroVariance(0);
  const PipelineRun run = RunPipeline(adaptive, sim::Regime::kWalking);
  ASSERT_EQ(run.scans.size(), fixed.scans.size());
  for (size_t i = 1; i < run.scans.size(); ++i) {
    ASSERT_EQ(run.expected[i], 1) << "scan " << i << " residual " << run.residual[i];
    EXPECT_EQ(run.marginalized[i], fixed.marginalized[i]);
    EXPECT_EQ(run.scans[i].T_mr.Matrix(), fixed.scans[i].T_mr.Matrix()) << "scan " << i;
    EXPECT_EQ(run.scans[i].velocity, fixed.scans[i].velocity) << "scan " << i;
  }
  // The same threshold splits every sweep of the fast sequence.
  const PipelineRun fast = RunPipeline(adaptive, sim::Regime::kFast);
  for (size_t i = 2; i < fast.scans.size(); ++i) {
    EXPECT_GE(fast.expected[i], 2) << "scan " << i << " residual " << fast.residual[i];
    EXPECT_EQ(fast.marginalized[i], fast.expected[i - 1]) << "scan " << i;
  }
}

// On the sweeps the rule splits, the IMU measurements are whitened with the variance floors: with
// floors 100× the configured variances the whitened χ² of the IMU blocks at the final estimates
// falls (the estimate moves away from the down-weighted samples, so by less than 100×: measured
// gyro 0.37×, accelerometer below 0.1×); a floor that did not reach the blocks would leave it.
TEST(KnotSpacing, SplitSweepsUseTheVarianceFloors) {
  OdometryConfig split = testing::SimLioConfig();
  split.adaptive_knots = Options(2, 1e-6);  // every sweep of the fast sequence split
  OdometryConfig floored = split;
  floored.adaptive_knots.accel_variance_floor = 100.0 * split.AccelVariance(0);
  floored.adaptive_knots.gyro_variance_floor = 100.0 * split.GyroVariance(0);
  const PipelineRun a = RunPipeline(split, sim::Regime::kFast);
  const PipelineRun b = RunPipeline(floored, sim::Regime::kFast);
  ASSERT_EQ(a.scans.size(), b.scans.size());
  double gyro_a = 0.0, gyro_b = 0.0, accel_a = 0.0, accel_b = 0.0;
  for (size_t i = 1; i < a.scans.size(); ++i) {
    ASSERT_EQ(a.expected[i], 2);
    ASSERT_NE(b.scans[i].status, ScanStatus::kFailed) << "scan " << i;
    gyro_a += a.scans[i].gyro_chi2;
    gyro_b += b.scans[i].gyro_chi2;
    accel_a += a.scans[i].accel_chi2;
    accel_b += b.scans[i].accel_chi2;
  }
  ASSERT_GT(gyro_a, 0.0);
  ASSERT_GT(accel_a, 0.0);
  EXPECT_LT(gyro_b, 0.5 * gyro_a);
  EXPECT_LT(accel_b, 0.1 * accel_a);
}

// window.adaptive_knots_max_keypoints: a split sweep registers up to that many keypoints instead
// of lidar_frontend.max_keypoints (each processed fast sweep above the front end's cap here), and
// a sweep the rule leaves whole keeps the front end's keypoints, so a walk's run is the run
// without the key bit for bit.
TEST(KnotSpacing, SplitSweepsGetTheirOwnKeypointBudget) {
  OdometryConfig base = testing::SimLioConfig();
  base.frontend.max_keypoints = 40;
  base.adaptive_knots = Options(2, 0.15);
  OdometryConfig budget = base;
  budget.adaptive_knots.max_keypoints = 120;
  const PipelineRun fast = RunPipeline(budget, sim::Regime::kFast);
  const PipelineRun fast_capped = RunPipeline(base, sim::Regime::kFast);
  ASSERT_EQ(fast.scans.size(), fast_capped.scans.size());
  int above = 0;
  for (size_t i = 2; i < fast.scans.size(); ++i) {  // from the second processed sweep on
    ASSERT_GE(fast.expected[i], 2) << "scan " << i;
    ASSERT_NE(fast.scans[i].status, ScanStatus::kFailed) << "scan " << i;
    EXPECT_LE(fast_capped.scans[i].keypoints, 40) << "scan " << i;
    EXPECT_LE(fast.scans[i].keypoints, 120) << "scan " << i;
    EXPECT_GE(fast.scans[i].keypoints, fast_capped.scans[i].keypoints) << "scan " << i;
    if (fast.scans[i].keypoints > 40) ++above;
  }
  EXPECT_GE(above, static_cast<int>(fast.scans.size()) - 3);
  const PipelineRun walk = RunPipeline(budget, sim::Regime::kWalking);
  const PipelineRun walk_capped = RunPipeline(base, sim::Regime::kWalking);
  ASSERT_EQ(walk.scans.size(), walk_capped.scans.size());
  for (size_t i = 1; i < walk.scans.size(); ++i) {
    ASSERT_EQ(walk.expected[i], 1) << "scan " << i;
    EXPECT_EQ(walk.scans[i].keypoints, walk_capped.scans[i].keypoints) << "scan " << i;
    EXPECT_EQ(walk.scans[i].T_mr.Matrix(), walk_capped.scans[i].T_mr.Matrix()) << "scan " << i;
  }
}

// The key is read and range-checked: a negative budget is an error naming the file and the key.
TEST(KnotSpacing, SplitSweepKeypointBudgetIsReadAndChecked) {
  const std::string path = ::testing::TempDir() + "/adaptive_knots_keypoints.yaml";
  std::ofstream(path) << "window:\n  adaptive_knots_max_keypoints: 800\n";
  EXPECT_EQ(LoadOdometryConfig(path).adaptive_knots.max_keypoints, 800);
  std::ofstream(path) << "window:\n  adaptive_knots_max_keypoints: -5\n";
  try {
    LoadOdometryConfig(path);
    ADD_FAILURE() << "a negative keypoint budget was accepted";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("adaptive_knots_max_keypoints"), std::string::npos) << what;
    EXPECT_NE(what.find("adaptive_knots_keypoints.yaml"), std::string::npos) << what;
  }
  OdometryConfig c;
  c.adaptive_knots.max_keypoints = -1;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::lio
