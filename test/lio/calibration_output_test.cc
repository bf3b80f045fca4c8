// The calibration a run recommends for a config (calibration_output.h,
// docs/user-guide/calibration.md): coordinates unobservable after most scans keep their start value
// instead of the estimate that drifted, in RecommendCalibration and in the calibration.yaml a user
// pastes; on constructed runs, and end to end in the slow regime (translation only), where the
// estimate drifts while the start is kept.
#include "lio/calibration_output.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/sim_lio.h"
#include "common/temp_dir.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "lio/run_odometry.h"

namespace ctlio::lioapp {
namespace {

// A run of `scans` scans that estimated δ_0 (from `start_offset`) and the extrinsic; scan k
// reports coordinate i unobservable when unobservable_until[i] > k (the first scan unassessed).
RunSummary ConstructedRun(int scans, const std::vector<int>& unobservable_until,
                          double start_offset, const SE3& start, const SE3& estimate) {
  RunSummary run;
  run.initial_extrinsic = start;
  run.initial_time_offsets = {start_offset};
  for (int k = 0; k < scans; ++k) {
    lio::ScanResult r;
    r.t_ns = 100'000'000LL * k;
    auto& c = r.calibration;
    c.time_offset_s = {0.0123};
    c.time_offset_sigma_s = {1e-3};
    c.has_extrinsic = true;
    c.T_imu_lidar = estimate;
    c.extrinsic_sigma = Vec6::Constant(0.01);
    if (k > 0) {
      for (int until : unobservable_until) {
        c.unobservable.push_back(k < until);
        c.observability.push_back(k < until ? 0.0 : 1.0);
      }
    }
    run.scans.push_back(r);
  }
  return run;
}

// The start and the last estimate of the extrinsic in the constructed runs (non-trivial both).
SE3 Start() {
  Vec6 x;
  x << 0.1, -0.05, 0.2, 0.3, -0.2, 1.0;
  return SE3::Exp(x);
}
SE3 Estimate() {
  Vec6 x;
  x << 0.03, 0.04, -0.02, 0.2, 0.1, -0.3;
  return SE3::Exp(x) * Start();
}

// 11 scans, 10 assessed, δ started at 2 ms. δ: unobservable in 8 of 10 (kept); ρ_x in 6 (kept);
// ρ_y in exactly 5 (not more than half: estimated); ρ_z never; φ_x in 10 (kept); φ_y, φ_z in 1.
RunSummary MostlyUnobservableRun() {
  return ConstructedRun(11, {9, 7, 6, 0, 11, 2, 2}, 0.002, Start(), Estimate());
}

// calibration.yaml of `run` with `recommended`, written to a fresh folder: its path and text.
std::pair<std::string, std::string> WrittenYaml(const RunSummary& run,
                                                const RecommendedCalibration& recommended) {
  const std::string path = (testing::FreshTempDir("calibration_output") / "c.yaml").string();
  EXPECT_TRUE(WriteCalibrationYaml(path, run, recommended));
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return {path, text.str()};
}

TEST(CalibrationOutput, UnobservableAfterMostScansKeepsTheStart) {
  const SE3 start = Start(), estimate = Estimate();
  const RunSummary run = MostlyUnobservableRun();
  const auto r = RecommendCalibration(run);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kept_at_start,
            (std::vector<std::string>{"time_offset_0", "extrinsic_rho_x", "extrinsic_phi_x"}));
  ASSERT_EQ(r->time_offset_s.size(), 1u);
  EXPECT_EQ(r->time_offset_s[0], 0.002);
  ASSERT_TRUE(r->has_extrinsic);
  // In calibration.csv's coordinates (left tangent at the start) the kept axes are zero and the
  // others the estimate's.
  const Vec6 moved = (estimate * start.Inverse()).Log();
  const Vec6 written = (r->T_imu_lidar * start.Inverse()).Log();
  for (int i : {0, 3}) {
    EXPECT_NEAR(written[i], 0.0, 1e-12) << i;
  }
  for (int i : {1, 2, 4, 5}) {
    EXPECT_NEAR(written[i], moved[i], 1e-12) << i;
  }

  // Asked not to keep: the last estimate as it is.
  const auto raw = RecommendCalibration(run, false);
  ASSERT_TRUE(raw.has_value());
  EXPECT_TRUE(raw->kept_at_start.empty());
  EXPECT_EQ(raw->time_offset_s[0], 0.0123);
  EXPECT_TRUE((raw->T_imu_lidar * estimate.Inverse()).Log().norm() < 1e-12);
}

TEST(CalibrationOutput, WithoutTheObservabilityCheckTheEstimateIsWritten) {
  const SE3 estimate = Estimate();
  const RunSummary run = ConstructedRun(5, {}, 0.0, Start(), estimate);
  const auto r = RecommendCalibration(run);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->kept_at_start.empty());
  EXPECT_EQ(r->time_offset_s[0], 0.0123);
  EXPECT_TRUE((r->T_imu_lidar * estimate.Inverse()).Log().norm() < 1e-12);
  EXPECT_FALSE(RecommendCalibration(RunSummary()).has_value());
  // Nothing kept: the yaml neither warns nor has a second, written extrinsic.
  const auto [path, text] = WrittenYaml(run, *r);
  EXPECT_EQ(text.find("NOT CALIBRATED"), std::string::npos) << text;
  EXPECT_EQ(text.find("# Written"), std::string::npos) << text;
}

TEST(CalibrationOutput, TheYamlIsTheRecommendationAndSaysWhatWasKept) {
  const RunSummary run = MostlyUnobservableRun();
  const auto r = RecommendCalibration(run);
  ASSERT_TRUE(r.has_value());
  const auto [path, text] = WrittenYaml(run, *r);
  EXPECT_NE(text.find("# NOT CALIBRATED"), std::string::npos) << text;
  EXPECT_NE(text.find("time_offset_0 (80%) extrinsic_rho_x (60%) extrinsic_phi_x (100%)"),
            std::string::npos)
      << text;
  // The written extrinsic's comment: the kept axes exactly at the start (ρ_x, φ_x).
  EXPECT_NE(text.find("# Written (the unobservable axes at the start): rho = [0, "),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("m, phi = [0, "), std::string::npos) << text;
  // What a config reads from it is the recommendation (9 significant digits).
  const YAML::Node y = YAML::LoadFile(path);
  EXPECT_NEAR(y["calibration"]["time_offset_s"][0].as<double>(), 0.002, 1e-12);
  const Mat3 R = r->T_imu_lidar.rotation();
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(y["extrinsic"]["rotation"][i].as<double>(), R(i / 3, i % 3), 1e-8) << i;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(y["extrinsic"]["translation"][i].as<double>(), r->T_imu_lidar.translation()[i],
                1e-8)
        << i;
  }
  std::ostringstream summary;
  WriteObservabilitySummary(run, r, summary);
  EXPECT_NE(summary.str().find(
                "calibration_kept_at_start time_offset_0 extrinsic_rho_x extrinsic_phi_x\n"),
            std::string::npos)
      << summary.str();
}

// Slow regime (translation only), both calibrations from the wrong start, the default (not held)
// estimation: the clock offset and the lever arm are unobservable after most scans and drift;
// the recommendation keeps their start (δ = 0, the nominal extrinsic's ρ) instead.
TEST(CalibrationOutput, SlowRegimeRecommendsTheStartWhereTheEstimateDrifted) {
  const sim::SimConfig c = testing::WrongCalibrationSequence(sim::Regime::kSlow, 6.0, 0.020);
  lio::OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  ASSERT_FALSE(config.calibration.hold_unobservable);
  sim::SimulatedSource source(c);
  const RunSummary run = RunOdometry(source, config);
  ASSERT_EQ(run.failed, 0) << run.first_failure;
  const auto r = RecommendCalibration(run);
  ASSERT_TRUE(r.has_value());
  const auto kept = [&](const std::string& name) {
    return std::find(r->kept_at_start.begin(), r->kept_at_start.end(), name) !=
           r->kept_at_start.end();
  };
  EXPECT_TRUE(kept("time_offset_0"));
  for (const char* a : {"x", "y", "z"}) {
    EXPECT_TRUE(kept(std::string("extrinsic_rho_") + a)) << a;
  }
  const lio::ScanResult* last = LastCalibration(run);
  ASSERT_NE(last, nullptr);
  // The estimate moved (δ off its start, the lever arm by more than a millimetre); the
  // recommendation did not, along the kept axes.
  EXPECT_GT(std::abs(last->calibration.time_offset_s[0]), 1e-3);
  EXPECT_EQ(r->time_offset_s[0], 0.0);
  const Vec6 moved = (last->calibration.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
  const Vec6 written = (r->T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
  EXPECT_GT(moved.head<3>().norm(), 1e-3);
  EXPECT_LT(written.head<3>().norm(), 1e-12);
}

}  // namespace
}  // namespace ctlio::lioapp
