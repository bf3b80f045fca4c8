// The calibration a run recommends for a config (calibration_output.h,
// docs/user-guide/calibration.md): per coordinate the estimate where its σ is below the threshold
// of its kind (calibration.write_max_sigma_*), else the start, whatever share of scans the
// observability check flagged; calibration.yaml shows estimate, σ, start, written value and why
// per coordinate and works as an overlay after the config. On constructed runs, and end to end in
// the slow regime (translation only).
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
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lioapp {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A run of `scans` scans that estimated δ_0 = 12.3 ms (from `start_offset`) with σ `offset_sigma`
// and the extrinsic `estimate` with σ `extrinsic_sigma`; scan k reports coordinate i
// unobservable when unobservable_until[i] > k (the first scan unassessed).
RunSummary ConstructedRun(int scans, const std::vector<int>& unobservable_until,
                          double start_offset, const SE3& start, const SE3& estimate,
                          double offset_sigma, const Vec6& extrinsic_sigma) {
  RunSummary run;
  run.method = "singer_lio";
  run.source = "constructed";
  run.initial_extrinsic = start;
  run.initial_time_offsets = {start_offset};
  for (int k = 0; k < scans; ++k) {
    lio::ScanResult r;
    r.t_ns = 100'000'000LL * k;
    auto& c = r.calibration;
    c.time_offset_s = {0.0123};
    c.time_offset_sigma_s = {offset_sigma};
    c.has_extrinsic = true;
    c.T_imu_lidar = estimate;
    c.extrinsic_sigma = extrinsic_sigma;
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

// σ per extrinsic coordinate [ρ (m); φ (rad)]: ρ_x 5 mm, φ_z 0.05° below their thresholds (1 cm,
// 0.1°); ρ_y 2 cm, φ_x 0.3° above; ρ_z exactly 1 cm and φ_y 0.1° (not below: kept).
Vec6 MixedSigma() {
  Vec6 s;
  s << 0.005, 0.02, 0.01, 0.3 * kDeg, 0.1 * kDeg, 0.05 * kDeg;
  return s;
}

// 101 scans, 100 assessed, δ started at 2 ms with σ 0.2 ms (below 0.5 ms) but flagged
// unobservable on 81 of them (issue 45's case); ρ_x flagged on all, φ_z on 90; ρ_y, φ_x never.
RunSummary FlaggedButInformedRun() {
  return ConstructedRun(101, {82, 101, 0, 51, 0, 0, 91}, 0.002, Start(), Estimate(), 2e-4,
                        MixedSigma());
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

TEST(CalibrationOutput, AnEstimateWithSmallSigmaIsWrittenWhateverShareWasFlagged) {
  const SE3 start = Start(), estimate = Estimate();
  const RunSummary run = FlaggedButInformedRun();
  const auto r = RecommendCalibration(run, lio::CalibrationOptions());
  ASSERT_TRUE(r.has_value());
  // δ (flagged on 81%, σ 0.2 ms), ρ_x (flagged on 100%, σ 5 mm) and φ_z (90%, 0.05°) are
  // written; ρ_y (never flagged, σ 2 cm), φ_x (never, 0.3°) and the two at their threshold not.
  EXPECT_EQ(r->kept_at_start, (std::vector<std::string>{"extrinsic_rho_y", "extrinsic_rho_z",
                                                        "extrinsic_phi_x", "extrinsic_phi_y"}));
  ASSERT_EQ(r->time_offset_s.size(), 1u);
  EXPECT_EQ(r->time_offset_s[0], 0.0123);
  ASSERT_EQ(r->coordinates.size(), 7u);
  EXPECT_TRUE(r->coordinates[0].estimate_written);
  EXPECT_NEAR(r->coordinates[0].unobservable_fraction, 0.81, 1e-12);
  EXPECT_DOUBLE_EQ(r->coordinates[0].threshold, 5e-4);
  EXPECT_NEAR(r->coordinates[1].unobservable_fraction, 1.0, 1e-12);
  // In calibration.csv's coordinates (left tangent at the start) the kept axes are zero and the
  // written ones the estimate's.
  const Vec6 moved = (estimate * start.Inverse()).Log();
  const Vec6 written = (r->T_imu_lidar * start.Inverse()).Log();
  for (int i : {1, 2, 3, 4}) {
    EXPECT_NEAR(written[i], 0.0, 1e-12) << i;
  }
  for (int i : {0, 5}) {
    EXPECT_NEAR(written[i], moved[i], 1e-12) << i;
  }
}

TEST(CalibrationOutput, AnEstimateWithLargeSigmaKeepsTheStart) {
  // δ with σ 1 ms, never flagged: the start (2 ms); every extrinsic σ 2 cm / 0.5°: the start.
  Vec6 sigma;
  sigma << 0.02, 0.02, 0.02, 0.5 * kDeg, 0.5 * kDeg, 0.5 * kDeg;
  const RunSummary run =
      ConstructedRun(11, {0, 0, 0, 0, 0, 0, 0}, 0.002, Start(), Estimate(), 1e-3, sigma);
  const auto r = RecommendCalibration(run, lio::CalibrationOptions());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kept_at_start.size(), 7u);
  EXPECT_EQ(r->time_offset_s[0], 0.002);
  EXPECT_TRUE((r->T_imu_lidar * Start().Inverse()).Log().norm() < 1e-12);
  EXPECT_NE(r->coordinates[0].reason.find("did not inform"), std::string::npos);
  // The thresholds are the config's: 2 ms, 1°, 5 cm write them all.
  lio::CalibrationOptions loose;
  loose.write_max_sigma_s = 2e-3;
  loose.write_max_sigma_deg = 1.0;
  loose.write_max_sigma_m = 0.05;
  const auto w = RecommendCalibration(run, loose);
  ASSERT_TRUE(w.has_value());
  EXPECT_TRUE(w->kept_at_start.empty());
  EXPECT_EQ(w->time_offset_s[0], 0.0123);
  EXPECT_TRUE((w->T_imu_lidar * Estimate().Inverse()).Log().norm() < 1e-12);
  // Asked not to keep: the last estimate as it is.
  const auto raw = RecommendCalibration(run, lio::CalibrationOptions(), false);
  ASSERT_TRUE(raw.has_value());
  EXPECT_TRUE(raw->kept_at_start.empty());
  EXPECT_EQ(raw->time_offset_s[0], 0.0123);
  EXPECT_TRUE((raw->T_imu_lidar * Estimate().Inverse()).Log().norm() < 1e-12);
  EXPECT_FALSE(RecommendCalibration(RunSummary(), lio::CalibrationOptions()).has_value());
}

TEST(CalibrationOutput, NoSigmaKeepsTheStart) {
  // A scan without a covariance reports σ 0 (the extrinsic) or NaN: not a certain estimate.
  const RunSummary run =
      ConstructedRun(3, {}, 0.0, Start(), Estimate(), std::nan(""), Vec6::Zero());
  const auto r = RecommendCalibration(run, lio::CalibrationOptions());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kept_at_start.size(), 7u);
  EXPECT_EQ(r->coordinates[0].unobservable_fraction, -1.0);  // never assessed
  EXPECT_NE(r->coordinates[3].reason.find("no sigma"), std::string::npos);
}

// calibration.yaml: per coordinate one block, top-down estimate, σ, start, written, why (and the
// share flagged as information); the keys are the recommendation, and the file is an overlay
// that gives a config the written calibration.
TEST(CalibrationOutput, TheYamlShowsEachCoordinateTopDownAndIsAnOverlay) {
  const RunSummary run = FlaggedButInformedRun();
  const auto r = RecommendCalibration(run, lio::CalibrationOptions());
  ASSERT_TRUE(r.has_value());
  const auto written = WrittenYaml(run, *r);
  const std::string& path = written.first;
  const std::string& text = written.second;
  const auto block = [&](const std::string& name) {
    const size_t at = text.find("# " + name + " [");
    EXPECT_NE(at, std::string::npos) << name << "\n" << text;
    const size_t end = text.find("#\n", at);
    return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
  };
  const std::string delta = block("time_offset_0");
  std::vector<size_t> order;
  for (const char* line : {"#   estimate   12.3\n", "#   sigma      0.2\n", "#   start      2\n",
                           "#   written    12.3\n", "#   why        the estimate"}) {
    order.push_back(delta.find(line));
    EXPECT_NE(order.back(), std::string::npos) << line << "\n" << delta;
  }
  EXPECT_TRUE(std::is_sorted(order.begin(), order.end())) << delta;
  EXPECT_NE(delta.find("threshold, 0.5 ms (calibration.write_max_sigma_s)\n"), std::string::npos)
      << delta;
  EXPECT_NE(delta.find("flagged unobservable after 81% of the scans"), std::string::npos) << delta;
  const std::string rho_y = block("extrinsic_rho_y");  // cm
  EXPECT_NE(rho_y.find("#   sigma      2\n"), std::string::npos) << rho_y;
  EXPECT_NE(rho_y.find("#   start      0\n#   written    0\n"), std::string::npos) << rho_y;
  EXPECT_NE(rho_y.find("threshold, 1 cm (calibration.write_max_sigma_m): the data did not inform"),
            std::string::npos)
      << rho_y;
  EXPECT_NE(block("extrinsic_phi_x").find("0.1 deg (calibration.write_max_sigma_deg)"),
            std::string::npos);
  EXPECT_EQ(text.find("NOT CALIBRATED"), std::string::npos);
  // What a config reads from it is the recommendation (9 significant digits).
  const YAML::Node y = YAML::LoadFile(path);
  EXPECT_NEAR(y["calibration"]["time_offset_s"][0].as<double>(), 0.0123, 1e-12);
  const Mat3 R = r->T_imu_lidar.rotation();
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(y["extrinsic"]["rotation"][i].as<double>(), R(i / 3, i % 3), 1e-8) << i;
  }
  // As an overlay after a config (--config my.yaml,calibration.yaml) with an xyz_rpy extrinsic.
  const std::string own = (testing::FreshTempDir("calibration_overlay") / "my.yaml").string();
  std::ofstream(own) << "extrinsic:\n  xyz_rpy: [1, 2, 3, 0.1, 0.2, 0.3]\n"
                     << "calibration:\n  time_offset_s: [0.002]\n  estimate_time_offset: true\n";
  const lio::OdometryConfig c = lio::LoadOdometryConfig(own + "," + path);
  EXPECT_NEAR(c.calibration.time_offset_s.at(0), 0.0123, 1e-12);
  EXPECT_TRUE(c.calibration.estimate_time_offset);  // my.yaml's
  EXPECT_LT((c.T_imu_lidar * r->T_imu_lidar.Inverse()).Log().norm(), 1e-7);
  std::ostringstream summary;
  WriteObservabilitySummary(run, r, summary);
  EXPECT_NE(summary.str().find("calibration_kept_at_start extrinsic_rho_y extrinsic_rho_z "
                               "extrinsic_phi_x extrinsic_phi_y\n"),
            std::string::npos)
      << summary.str();
}

TEST(CalibrationOutput, WithoutTheObservabilityCheckTheRuleIsTheSame) {
  const RunSummary run = ConstructedRun(5, {}, 0.0, Start(), Estimate(), 2e-4, MixedSigma());
  const auto r = RecommendCalibration(run, lio::CalibrationOptions());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->kept_at_start.size(), 4u);
  EXPECT_EQ(r->time_offset_s[0], 0.0123);
  const auto [path, text] = WrittenYaml(run, *r);
  EXPECT_EQ(text.find("flagged"), std::string::npos) << text;
  std::ostringstream summary;
  WriteObservabilitySummary(run, r, summary);
  EXPECT_EQ(summary.str(),
            "calibration_kept_at_start extrinsic_rho_y extrinsic_rho_z "
            "extrinsic_phi_x extrinsic_phi_y\n");
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
  const auto r = RecommendCalibration(run, config.calibration);
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
