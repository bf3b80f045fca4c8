// Configs composed on the command line (`--config a.yaml,b.yaml`, config_composition.h): later
// files win key by key as `base:` does, errors name the file and line, and the calibration overlay
// layers on every shipped config.
#include "ctlio/solvers/lio/config_composition.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_paths.h"
#include "common/write_temp.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {
namespace {

using ctlio::testing::WriteTemp;

// The error LoadOdometryConfig(spec) throws ("no error" when it loads).
std::string LoadError(const std::string& spec) {
  try {
    LoadOdometryConfig(spec);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

// `--config a.yaml,b.yaml`: later files win key by key, as `base:` does; the result is the same
// as b.yaml naming a.yaml in `base:`.
TEST(OdometryConfigComposition, LaterFilesWinKeyByKey) {
  const std::string a = WriteTemp(
      "compose_a.yaml", "window:\n  knots: 3\n  threads: 2\ngp:\n  qc: [1, 2, 3, 4, 5, 6]\n");
  const std::string b = WriteTemp("compose_b.yaml", "window:\n  knots: 5\n");
  const OdometryConfig c = LoadOdometryConfig(a + "," + b);
  EXPECT_EQ(c.window_knots, 5);    // b's
  EXPECT_EQ(c.solver_threads, 2);  // a's, beside b's key in the same section
  EXPECT_DOUBLE_EQ(c.qc[5], 6);
  EXPECT_EQ(LoadOdometryConfig(b + " , " + a).window_knots, 3);  // the other order; spaces trimmed
  const OdometryConfig via_base = LoadOdometryConfig(
      WriteTemp("compose_b_base.yaml", "base: compose_a.yaml\nwindow:\n  knots: 5\n"));
  EXPECT_EQ(via_base.window_knots, c.window_knots);
  EXPECT_EQ(via_base.solver_threads, c.solver_threads);
  EXPECT_EQ(SplitConfigList("x.yaml, y.yaml,z.yaml"),
            (std::vector<std::string>{"x.yaml", "y.yaml", "z.yaml"}));
  // A file whose name has a comma stays one file.
  const std::string comma = WriteTemp("compose,comma.yaml", "window:\n  knots: 7\n");
  EXPECT_EQ(SplitConfigList(comma), std::vector<std::string>{comma});
  EXPECT_EQ(LoadOdometryConfig(comma).window_knots, 7);
  EXPECT_NE(LoadError(a + ",," + b).find("an empty file name"), std::string::npos);
  EXPECT_NE(LoadError(a + ",").find("an empty file name"), std::string::npos);
}

// An error names the file and line of the offending key in whichever file of the composition.
TEST(OdometryConfigComposition, ErrorsNameTheFileAndLine) {
  const std::string good = WriteTemp("compose_good.yaml", "window:\n  knots: 3\n");
  const std::string bad = WriteTemp("compose_bad.yaml", "window:\n  knots: 3\n  knotz: 2\n");
  for (const std::string& spec : {good + "," + bad, bad + "," + good}) {
    const std::string m = LoadError(spec);
    EXPECT_NE(m.find(bad + ":3: unknown key 'window.knotz'"), std::string::npos) << m;
  }
  const std::string range =
      WriteTemp("compose_range.yaml", "# a comment\nwindow:\n  threads: 100000\n");
  std::string m = LoadError(good + "," + range);
  EXPECT_NE(m.find(range + ":3: window.threads = 100000 is out of range"), std::string::npos) << m;
  m = LoadError(good + "," + ::testing::TempDir() + "/compose_missing.yaml");
  EXPECT_NE(m.find("compose_missing.yaml: cannot open"), std::string::npos) << m;
  // A list in `base:`: a base's error names the base's file and line after the `base:` line.
  const std::string top = WriteTemp(
      "compose_top.yaml", "window:\n  knots: 4\nbase: [compose_good.yaml, compose_bad.yaml]\n");
  m = LoadError(top);
  EXPECT_NE(m.find(top + ":3: base: "), std::string::npos) << m;
  EXPECT_NE(m.find("compose_bad.yaml:3: unknown key 'window.knotz'"), std::string::npos) << m;
  const std::string not_a_path = WriteTemp("compose_base_map.yaml", "base: {a: 1}\n");
  EXPECT_NE(LoadError(not_a_path).find(not_a_path + ":1: base: must be the path"),
            std::string::npos);
}

// data/calibration.yaml has no `base:` and works on top of every shipped config: its keys set,
// every other key the config's own (the extrinsic and the IMU noise of the data).
TEST(OdometryConfigComposition, CalibrationOverlayWorksOnEveryShippedConfig) {
  const std::string dir = ctlio::testing::SourceDir() + "/data/";
  EXPECT_FALSE(YAML::LoadFile(dir + "calibration.yaml")["base"].IsDefined());
  for (const std::string name : {"sim_lio.yaml", "newer_college_lio.yaml"}) {
    SCOPED_TRACE(name);
    const OdometryConfig own = LoadOdometryConfig(dir + name);
    const OdometryConfig cal = LoadOdometryConfig(dir + name + "," + dir + "calibration.yaml");
    EXPECT_TRUE(cal.calibration.estimate_time_offset);
    EXPECT_TRUE(cal.calibration.estimate_extrinsic);
    EXPECT_DOUBLE_EQ(cal.calibration.warmup_replay_s, 12.0);
    EXPECT_EQ(cal.calibration.warmup_replay_passes, 2);
    EXPECT_TRUE(cal.calibration.warmup_replay_hold);
    EXPECT_EQ(cal.knots_per_scan, 2);
    EXPECT_TRUE(cal.imu_prediction);
    EXPECT_EQ(cal.frontend.max_keypoints, 2400);
    EXPECT_EQ(cal.input_interpolation, "cubic");  // the baseline's, calibration.md
    EXPECT_EQ(cal.input_substeps, 4);
    EXPECT_DOUBLE_EQ(cal.calibration.write_max_sigma_s, 5e-4);
    EXPECT_DOUBLE_EQ(cal.calibration.write_max_sigma_deg, 0.1);
    EXPECT_DOUBLE_EQ(cal.calibration.write_max_sigma_m, 0.01);
    EXPECT_EQ(cal.method, own.method);
    EXPECT_EQ((cal.T_imu_lidar * own.T_imu_lidar.Inverse()).Log().norm(), 0.0);
    EXPECT_DOUBLE_EQ(cal.accel_variance, own.accel_variance);
    EXPECT_DOUBLE_EQ(cal.frontend.voxel_size, own.frontend.voxel_size);
    EXPECT_EQ(cal.qc, own.qc);
    // Singer-LIO's denser keypoints (per_method.singer_lio), every other method the file's.
    const OdometryConfig singer = cal.ForMethod(LioMethod::kSingerLio);
    EXPECT_EQ(singer.frontend.max_keypoints, 4800);
    EXPECT_DOUBLE_EQ(singer.frontend.voxel_size, 0.5);
    EXPECT_DOUBLE_EQ(singer.frontend.initial_voxel_size, 0.5);
    EXPECT_DOUBLE_EQ(singer.frontend.keypoint_voxel_size, 0.5);
    EXPECT_TRUE(singer.calibration.estimate_extrinsic);
    EXPECT_EQ(cal.per_method.size(),
              own.per_method.size() + (own.per_method.count(LioMethod::kSingerLio) ? 0 : 1));
    const OdometryConfig baseline = cal.ForMethod(LioMethod::kImuInput);
    EXPECT_DOUBLE_EQ(baseline.frontend.voxel_size,
                     own.ForMethod(LioMethod::kImuInput).frontend.voxel_size);
  }
  // data/sim_lio_calibration.yaml is that composition on sim_lio.yaml plus the simulated
  // sensors' keys.
  const OdometryConfig composed =
      LoadOdometryConfig(dir + "sim_lio.yaml," + dir + "calibration.yaml");
  const OdometryConfig sim_cal = LoadOdometryConfig(dir + "sim_lio_calibration.yaml");
  EXPECT_EQ(sim_cal.knots_per_scan, composed.knots_per_scan);
  EXPECT_EQ(sim_cal.frontend.max_keypoints, composed.frontend.max_keypoints);
  EXPECT_EQ(sim_cal.calibration.warmup_replay_hold, composed.calibration.warmup_replay_hold);
  EXPECT_DOUBLE_EQ(sim_cal.accel_variance, 0.16);
  EXPECT_NE(composed.accel_variance, 0.16);
}

// The thresholds of the written calibration: keys of `calibration`, finite and > 0, an error
// naming file, line and key otherwise.
TEST(OdometryConfigComposition, WriteThresholdKeys) {
  const OdometryConfig c = LoadOdometryConfig(
      WriteTemp("write_sigma.yaml",
                "calibration:\n  write_max_sigma_s: 0.001\n  write_max_sigma_deg: 0.2\n"
                "  write_max_sigma_m: 0.02\n"));
  EXPECT_DOUBLE_EQ(c.calibration.write_max_sigma_s, 0.001);
  EXPECT_DOUBLE_EQ(c.calibration.write_max_sigma_deg, 0.2);
  EXPECT_DOUBLE_EQ(c.calibration.write_max_sigma_m, 0.02);
  for (const std::string v : {"0", "-1", ".nan", ".inf"}) {
    const std::string path =
        WriteTemp("write_sigma_bad.yaml", "calibration:\n  write_max_sigma_m: " + v + "\n");
    const std::string m = LoadError(path);
    EXPECT_NE(m.find(path + ":2: calibration.write_max_sigma_m = " + v + " must be finite and > 0"),
              std::string::npos)
        << m;
  }
  // The informed-estimate rule's two keys; out of range, an error naming the key.
  const OdometryConfig r =
      LoadOdometryConfig(WriteTemp("write_ratio.yaml",
                                   "calibration:\n  write_max_sigma_ratio: 0.2\n"
                                   "  write_max_unobservable_fraction: 0.3\n"));
  EXPECT_DOUBLE_EQ(r.calibration.write_max_sigma_ratio, 0.2);
  EXPECT_DOUBLE_EQ(r.calibration.write_max_unobservable_fraction, 0.3);
  EXPECT_DOUBLE_EQ(OdometryConfig().calibration.write_max_sigma_ratio, 0.1);
  EXPECT_DOUBLE_EQ(OdometryConfig().calibration.write_max_unobservable_fraction, 0.5);
  for (const std::string key : {"write_max_sigma_ratio", "write_max_unobservable_fraction"}) {
    const std::string m =
        LoadError(WriteTemp("write_ratio_bad.yaml", "calibration:\n  " + key + ": 1.5\n"));
    EXPECT_NE(m.find("calibration." + key + " must be in"), std::string::npos) << m;
  }
  // The drift check's key: read, default 2.5, negative an error naming the key.
  EXPECT_DOUBLE_EQ(LoadOdometryConfig(
                       WriteTemp("write_drift.yaml", "calibration:\n  write_max_drift_sigmas: 4\n"))
                       .calibration.write_max_drift_sigmas,
                   4.0);
  EXPECT_DOUBLE_EQ(OdometryConfig().calibration.write_max_drift_sigmas, 2.5);
  const std::string m =
      LoadError(WriteTemp("write_drift_bad.yaml", "calibration:\n  write_max_drift_sigmas: -1\n"));
  EXPECT_NE(m.find("calibration.write_max_drift_sigmas must be finite and >= 0"), std::string::npos)
      << m;
}

// The translation of `extrinsic:` wins over xyz_rpy's whatever the key order, so a written
// calibration.yaml (rotation, translation) put after a config with xyz_rpy gives its extrinsic.
TEST(OdometryConfigComposition, WrittenExtrinsicWinsOverXyzRpy) {
  const std::string own =
      WriteTemp("ext_own.yaml", "extrinsic:\n  xyz_rpy: [1, 2, 3, 0, 0, 0.5]\n");
  const std::string written = WriteTemp(
      "ext_written.yaml",
      "extrinsic:\n  rotation: [0, -1, 0, 1, 0, 0, 0, 0, 1]\n  translation: [0.1, 0.2, 0.3]\n");
  const OdometryConfig c = LoadOdometryConfig(own + "," + written);
  EXPECT_TRUE(c.T_imu_lidar.translation().isApprox(Vec3(0.1, 0.2, 0.3)));
  EXPECT_NEAR(c.T_imu_lidar.rotation()(1, 0), 1.0, 1e-12);
  // In one file, translation before xyz_rpy: still the translation's.
  const OdometryConfig one = LoadOdometryConfig(WriteTemp(
      "ext_one.yaml", "extrinsic:\n  translation: [4, 5, 6]\n  xyz_rpy: [1, 2, 3, 0, 0, 0]\n"));
  EXPECT_TRUE(one.T_imu_lidar.translation().isApprox(Vec3(4, 5, 6)));
}

}  // namespace
}  // namespace ctlio::lio
