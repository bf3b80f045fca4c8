// Odometry configuration: shipped configs load, bad files name file and line.
#include "ctlio/solvers/lio/odometry_config.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <string>
#include <vector>

#include "common/test_paths.h"
#include "common/write_temp.h"
#include "ctlio/solvers/lio/config_composition.h"

namespace ctlio::lio {
namespace {

using ctlio::testing::WriteTemp;

TEST(OdometryConfig, DefaultAccelerometerModelIsTheExactOne) {
  // The paper's body-centric model (false) is chosen explicitly; an empty config keeps the exact
  // specific force.
  EXPECT_TRUE(OdometryConfig().exact_specific_force);
  EXPECT_TRUE(LoadOdometryConfig(WriteTemp("empty_imu.yaml", "imu: {}\n")).exact_specific_force);
  EXPECT_FALSE(LoadOdometryConfig(WriteTemp("paper.yaml", "imu:\n  exact_specific_force: false\n"))
                   .exact_specific_force);
}

TEST(OdometryConfig, DefaultBaselineIntegrationIsTheMidpointOne) {
  // The paper's zero-order hold (false) is chosen explicitly, as the accelerometer model above.
  EXPECT_TRUE(OdometryConfig().input_midpoint);
  EXPECT_TRUE(LoadOdometryConfig(WriteTemp("empty_imu2.yaml", "imu: {}\n")).input_midpoint);
  EXPECT_FALSE(
      LoadOdometryConfig(WriteTemp("zoh.yaml", "imu:\n  input_midpoint: false\n")).input_midpoint);
}

// The baseline's reading of the signal between samples (imu.input_interpolation, input_substeps;
// docs/experiments/calibration.md): defaults unchanged, read, and range-checked with the file.
TEST(OdometryConfig, BaselineInterpolationAndSubstepsAreReadAndChecked) {
  EXPECT_EQ(OdometryConfig().input_interpolation, "linear");
  EXPECT_EQ(OdometryConfig().input_substeps, 1);
  const OdometryConfig c = LoadOdometryConfig(
      WriteTemp("cubic.yaml", "imu:\n  input_interpolation: cubic\n  input_substeps: 4\n"));
  EXPECT_EQ(c.input_interpolation, "cubic");
  EXPECT_EQ(c.input_substeps, 4);
  for (const char* n : {"0", "17", "-2"}) {
    const std::string path =
        WriteTemp("substeps.yaml", std::string("imu:\n  input_substeps: ") + n + "\n");
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << n << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":2: imu.input_substeps = " + n +
                                           " is out of range: must be in [1, 16]"),
                std::string::npos)
          << e.what();
    }
  }
  const auto error = [](const std::string& name, const std::string& text) {
    try {
      LoadOdometryConfig(WriteTemp(name, text));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("quad.yaml", "imu:\n  input_interpolation: quadratic\n")
                .find("imu.input_interpolation must be linear or cubic"),
            std::string::npos);
  EXPECT_NE(error("held.yaml", "imu:\n  input_midpoint: false\n  input_interpolation: cubic\n")
                .find("need imu.input_midpoint: true"),
            std::string::npos);
  EXPECT_NE(error("held4.yaml", "imu:\n  input_midpoint: false\n  input_substeps: 4\n")
                .find("need imu.input_midpoint: true"),
            std::string::npos);
}

TEST(OdometryConfig, ShippedConfigsLoad) {
  const OdometryConfig sim = LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  EXPECT_EQ(sim.method, LioMethod::kSingerLio);
  EXPECT_TRUE(sim.exact_specific_force);
  EXPECT_FALSE(sim.overlap_stages);  // one thread unless asked
  EXPECT_TRUE(
      LoadOdometryConfig(WriteTemp("overlap.yaml", "window:\n  overlap: true\n")).overlap_stages);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("overlap_bad.yaml", "window:\n  overlap: 2x\n")),
               std::runtime_error);
  const OdometryConfig nc =
      LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/newer_college_lio.yaml");
  // SPEC §4: the paper's Newer College values where the file keeps them.
  EXPECT_DOUBLE_EQ(nc.qc[0], 5000);
  EXPECT_DOUBLE_EQ(nc.qc[3], 500);
  EXPECT_DOUBLE_EQ(nc.alpha[3], 100);
  EXPECT_DOUBLE_EQ(nc.accel_variance, 0.156);
  EXPECT_DOUBLE_EQ(nc.gyro_variance, 4.326e-4);
  EXPECT_DOUBLE_EQ(nc.gravity, 9.81599);
  // The published lidar→IMU extrinsic: rotation diag(−1, −1, 1).
  EXPECT_NEAR(nc.T_imu_lidar.rotation()(0, 0), -1.0, 1e-12);
  EXPECT_NEAR(nc.T_imu_lidar.translation().x(), -0.006253, 1e-12);
  // The exact specific force, a bounded per-scan cost, and the baseline's own override.
  EXPECT_TRUE(nc.exact_specific_force);
  EXPECT_GT(nc.frontend.max_keypoints, 0);
  const OdometryConfig nc_input = nc.ForMethod(LioMethod::kImuInput);
  EXPECT_GT(nc_input.frontend.max_iterations, nc.frontend.max_iterations);
  EXPECT_GE(nc_input.frontend.max_keypoints, nc.frontend.max_keypoints);
  EXPECT_DOUBLE_EQ(nc_input.qc[0], nc.qc[0]);  // keys it does not name: the base's
  EXPECT_EQ(nc.ForMethod(LioMethod::kSingerLio).frontend.max_iterations,
            nc.frontend.max_iterations);
}

TEST(OdometryConfig, UnknownKeyNamesFileAndLine) {
  const std::string path = WriteTemp("bad_key.yaml", "gp:\n  qc: [1, 1, 1, 1, 1, 1]\n  alfa: 3\n");
  try {
    LoadOdometryConfig(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gp.alfa"), std::string::npos) << e.what();
  }
}

TEST(OdometryConfig, BadValuesAreErrors) {
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("m.yaml", "method: kalman\n")), std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("q.yaml", "gp:\n  qc: [1, 2, 3]\n")),
               std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("n.yaml", "imu:\n  gyro_variance: -1\n")),
               std::runtime_error);
  EXPECT_THROW(
      LoadOdometryConfig(WriteTemp("r.yaml", "extrinsic:\n  rotation: [1,0,0,0,1,0,0,0,2]\n")),
      std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig("/nonexistent/odometry.yaml"), std::runtime_error);
  EXPECT_THROW(ParseLioMethod("singer"), std::invalid_argument);
  for (const char* k : {"0", "11", "1.5"}) {
    EXPECT_THROW(LoadOdometryConfig(
                     WriteTemp("k.yaml", std::string("window:\n  knots_per_scan: ") + k + "\n")),
                 std::runtime_error)
        << k;
  }
  // A gravity window of 1e30 s overflowed its nanoseconds (signed overflow, found by the bad-input
  // probe under UBSan): an error naming the key and the range.
  for (const char* d : {"1e30", "3601", ".inf"}) {
    try {
      LoadOdometryConfig(
          WriteTemp("g.yaml", std::string("init:\n  gravity_duration: ") + d + "\n"));
      ADD_FAILURE() << d << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("init.gravity_duration must be in [0, 3600] s"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(LoadOdometryConfig(WriteTemp("g.yaml", "init:\n  gravity_duration: 3600\n")));
}

// NaN or Inf anywhere in an extrinsic is an error naming the file, the line and the element (NaN
// passes the rotation-matrix check, whose comparisons are false, and gave a NaN trajectory).
TEST(OdometryConfig, NonFiniteExtrinsicNamesFileAndLine) {
  struct Case {
    const char* name;
    const char* text;
    const char* needle;
  };
  const Case cases[] = {
      {"e_rpy.yaml", "method: singer_lio\nextrinsic:\n  xyz_rpy: [0, 0, 0, .nan, 0, 0]\n",
       ":3: extrinsic.xyz_rpy[3] is .nan"},
      {"e_xyz.yaml", "extrinsic:\n  xyz_rpy: [0, .inf, 0, 0, 0, 0]\n",
       ":2: extrinsic.xyz_rpy[1] is .inf"},
      {"e_rot.yaml",
       "extrinsic:\n  rotation: [1, 0, 0,\n             0, .nan, 0,\n             0, 0, 1]\n",
       ":3: extrinsic.rotation[4] is .nan"},
      {"e_t.yaml", "extrinsic:\n  translation: [-.inf, 0, 0]\n",
       ":2: extrinsic.translation[0] is -.inf"},
      {"e_imu.yaml", "imus:\n  - xyz_rpy: [0, 0, 0, 0, .NaN, 0]\n",
       ":2: imus[0].xyz_rpy[4] is .NaN"},
  };
  for (const Case& c : cases) {
    const std::string path = WriteTemp(c.name, c.text);
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + c.needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("must be finite"), std::string::npos) << e.what();
    }
  }
  // Finite values still load.
  EXPECT_NEAR(LoadOdometryConfig(WriteTemp("e_ok.yaml", "extrinsic:\n  translation: [1, 2, 3]\n"))
                  .T_imu_lidar.translation()
                  .z(),
              3.0, 1e-15);
}

// Count keys out of range are errors naming the file, the line, the key and the range (a huge
// window.threads used to abort inside thread creation); Validate has the same bounds for library
// users.
TEST(OdometryConfig, CountKeysOutOfRangeNameFileLineKeyAndRange) {
  struct Case {
    const char* name;
    const char* text;
    const char* needle;
  };
  const Case cases[] = {
      {"t_huge.yaml", "window:\n  knots: 2\n  threads: 100000\n",
       ":3: window.threads = 100000 is out of range: must be in [1, 256]"},
      {"t_zero.yaml", "window:\n  threads: 0\n", ":2: window.threads = 0 is out of range"},
      {"knots.yaml", "window:\n  knots: 1000000\n", ":2: window.knots = 1000000 is out of range"},
      {"ft.yaml", "lidar_frontend:\n  threads: 65536\n",
       ":2: lidar_frontend.threads = 65536 is out of range: must be in [1, 256]"},
      {"ft_neg.yaml", "lidar_frontend:\n  threads: -4\n", ":2: lidar_frontend.threads = -4"},
      {"voxel.yaml", "lidar_frontend:\n  voxel_size: 0.5\n  max_points_per_voxel: 2000000000\n",
       ":3: lidar_frontend.max_points_per_voxel = 2000000000 is out of range: must be in [1, "
       "10000]"},
      {"neigh.yaml", "lidar_frontend:\n  max_neighbours: 99999\n",
       ":2: lidar_frontend.max_neighbours = 99999 is out of range"},
      {"angle.yaml", "lidar_frontend:\n  point_noise_angle: 0.5\n",
       ":2: lidar_frontend.point_noise_angle = 0.5 is out of range: must be in [0"},
      {"angle_neg.yaml", "lidar_frontend:\n  point_noise_angle: -0.001\n",
       ":2: lidar_frontend.point_noise_angle = -0.001 is out of range"},
      {"angle_nan.yaml", "lidar_frontend:\n  point_noise_angle: .nan\n",
       ":2: lidar_frontend.point_noise_angle = .nan is out of range"},
      {"per_method.yaml", "per_method:\n  imu_input:\n    window:\n      threads: 512\n",
       ":4: per_method.imu_input.window.threads = 512 is out of range"},
  };
  for (const Case& c : cases) {
    const std::string path = WriteTemp(c.name, c.text);
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + c.needle), std::string::npos) << e.what();
    }
  }
  OdometryConfig config;
  config.solver_threads = 257;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.solver_threads = 256;
  config.frontend.threads = 1000;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.frontend.threads = 2;
  config.frontend.max_points_per_voxel = 10001;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config.frontend.max_points_per_voxel = 20;
  EXPECT_NO_THROW(config.Validate());
  // A voxel wider than the range: a few points per sweep, the lidar fixes no pose (the probe's
  // voxel_size 1e30 ran with exit 0 at 5x the clean ATE).
  for (double* size : {&config.frontend.voxel_size, &config.frontend.initial_voxel_size,
                       &config.frontend.keypoint_voxel_size, &config.frontend.map_voxel_size}) {
    const double kept = *size;
    *size = 1e30;
    try {
      config.Validate();
      ADD_FAILURE() << "voxel size 1e30 accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("must not exceed max_range"), std::string::npos)
          << e.what();
    }
    *size = config.frontend.max_range;
    EXPECT_NO_THROW(config.Validate());
    *size = kept;
  }
}

TEST(OdometryConfig, KnotsPerScan) {
  EXPECT_EQ(OdometryConfig().knots_per_scan, 1);
  EXPECT_EQ(
      LoadOdometryConfig(WriteTemp("k2.yaml", "window:\n  knots_per_scan: 2\n")).knots_per_scan, 2);
}

TEST(OdometryConfig, ImuPrediction) {
  EXPECT_FALSE(OdometryConfig().imu_prediction);
  EXPECT_TRUE(
      LoadOdometryConfig(WriteTemp("p.yaml", "window:\n  imu_prediction: true\n")).imu_prediction);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("p2.yaml", "window:\n  imu_prediction: 3\n")),
               std::runtime_error);
}

TEST(OdometryConfig, CalibrationSection) {
  // Off by default (and in the shipped configs).
  const OdometryConfig sim = LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  EXPECT_FALSE(sim.calibration.any());
  const OdometryConfig c = LoadOdometryConfig(
      WriteTemp("cal.yaml",
                "calibration:\n  estimate_time_offset: true\n  time_offset_s: [0.02]\n"
                "  time_offset_prior_sigma_s: 0.05\n  estimate_extrinsic: true\n"
                "  extrinsic_prior_sigma_deg: 3\n  extrinsic_prior_sigma_m: 0.1\n"));
  EXPECT_TRUE(c.calibration.estimate_time_offset);
  EXPECT_TRUE(c.calibration.estimate_extrinsic);
  ASSERT_EQ(c.calibration.time_offset_s.size(), 1u);
  EXPECT_DOUBLE_EQ(c.calibration.TimeOffset(0), 0.02);
  EXPECT_DOUBLE_EQ(c.calibration.time_offset_prior_sigma_s, 0.05);
  EXPECT_DOUBLE_EQ(c.calibration.extrinsic_prior_sigma_deg, 3.0);
  EXPECT_DOUBLE_EQ(c.calibration.extrinsic_prior_sigma_m, 0.1);
  // Bad values name file and line; the section is not per method; one offset per IMU of imus.
  const std::string bad = WriteTemp("cal_bad.yaml", "calibration:\n  time_offset_s: 0.02x\n");
  try {
    LoadOdometryConfig(bad);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ":2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      LoadOdometryConfig(WriteTemp("cal_s.yaml", "calibration:\n  time_offset_prior_sigma_s: 0\n")),
      std::runtime_error);
  // The observability check's keys (calibration_observability.h).
  const OdometryConfig o =
      LoadOdometryConfig(WriteTemp("cal_o.yaml",
                                   "calibration:\n  observability_horizon_scans: 7\n"
                                   "  time_offset_observability_threshold: 2\n"
                                   "  rotation_observability_threshold: 0.5\n"
                                   "  translation_observability_threshold: 0.01\n"
                                   "  hold_unobservable: false\n  hold_information: 1e6\n"));
  EXPECT_EQ(o.calibration.observability_horizon_scans, 7);
  EXPECT_DOUBLE_EQ(o.calibration.time_offset_observability_threshold, 2.0);
  EXPECT_DOUBLE_EQ(o.calibration.rotation_observability_threshold, 0.5);
  EXPECT_DOUBLE_EQ(o.calibration.translation_observability_threshold, 0.01);
  EXPECT_FALSE(o.calibration.hold_unobservable);
  EXPECT_DOUBLE_EQ(o.calibration.hold_information, 1e6);
  EXPECT_THROW(LoadOdometryConfig(
                   WriteTemp("cal_h.yaml", "calibration:\n  observability_horizon_scans: -1\n")),
               std::runtime_error);
  // The warm-up replay (calibrating_odometry.h): off by default, and only for an estimated
  // calibration.
  EXPECT_DOUBLE_EQ(o.calibration.warmup_replay_s, 0.0);
  EXPECT_FALSE(c.calibration.replays_warmup());
  const OdometryConfig w = LoadOdometryConfig(WriteTemp(
      "cal_w.yaml", "calibration:\n  estimate_time_offset: true\n  warmup_replay_s: 2\n"));
  EXPECT_TRUE(w.calibration.replays_warmup());
  EXPECT_DOUBLE_EQ(w.calibration.warmup_replay_s, 2.0);
  EXPECT_EQ(w.calibration.warmup_replay_passes, 1);
  EXPECT_FALSE(w.calibration.warmup_replay_hold);
  const OdometryConfig wp = LoadOdometryConfig(
      WriteTemp("cal_wp.yaml",
                "calibration:\n  estimate_extrinsic: true\n  warmup_replay_s: 4\n"
                "  warmup_replay_passes: 2\n  warmup_replay_hold: true\n"));
  EXPECT_EQ(wp.calibration.warmup_replay_passes, 2);
  EXPECT_TRUE(wp.calibration.warmup_replay_hold);
  EXPECT_FALSE(wp.calibration.warmup_replay_freeze);
  const OdometryConfig wf = LoadOdometryConfig(
      WriteTemp("cal_wf.yaml",
                "calibration:\n  estimate_extrinsic: true\n  warmup_replay_s: 4\n"
                "  warmup_replay_passes: 2\n  warmup_replay_freeze: true\n"));
  EXPECT_TRUE(wf.calibration.warmup_replay_freeze);
  EXPECT_FALSE(wf.calibration.warmup_replay_hold);
  // The last pass either holds the span or freezes the values: not both.
  EXPECT_THROW(LoadOdometryConfig(
                   WriteTemp("cal_wfh.yaml",
                             "calibration:\n  estimate_extrinsic: true\n  warmup_replay_s: 4\n"
                             "  warmup_replay_hold: true\n  warmup_replay_freeze: true\n")),
               std::runtime_error);
  for (const char* without_span :
       {"warmup_replay_passes: 2", "warmup_replay_hold: true", "warmup_replay_freeze: true"}) {
    EXPECT_THROW(LoadOdometryConfig(
                     WriteTemp("cal_wps.yaml", std::string("calibration:\n  estimate_extrinsic: "
                                                           "true\n  ") +
                                                   without_span + "\n")),
                 std::runtime_error)
        << without_span;
  }
  for (const char* bad_passes : {"0", "11", "1.5"}) {
    EXPECT_THROW(LoadOdometryConfig(
                     WriteTemp("cal_wpb.yaml", std::string("calibration:\n  warmup_replay_s: 1\n"
                                                           "  warmup_replay_passes: ") +
                                                   bad_passes + "\n")),
                 std::runtime_error)
        << bad_passes;
  }
  const OdometryConfig n =
      LoadOdometryConfig(WriteTemp("cal_wn.yaml", "calibration:\n  warmup_replay_s: 2\n"));
  EXPECT_FALSE(n.calibration.replays_warmup());  // nothing estimated: nothing to replay
  for (const char* bad_span : {"-1", "61", ".nan"}) {
    EXPECT_THROW(LoadOdometryConfig(WriteTemp("cal_wb.yaml", std::string("calibration:\n  "
                                                                         "warmup_replay_s: ") +
                                                                 bad_span + "\n")),
                 std::runtime_error)
        << bad_span;
  }
  EXPECT_THROW(LoadOdometryConfig(WriteTemp(
                   "cal_t.yaml", "calibration:\n  rotation_observability_threshold: -1\n")),
               std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig(
                   WriteTemp("cal_pm.yaml", "per_method:\n  lidar_gyro:\n    calibration: {}\n")),
               std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("cal_n.yaml",
                                            "imus:\n  - {xyz_rpy: [0, 0, 0, 0, 0, 0]}\n"
                                            "  - {xyz_rpy: [0, 0, 0, 0, 0, 0]}\n"
                                            "calibration:\n  time_offset_s: [0.01]\n")),
               std::runtime_error);
}

// data/sim_lio_calibration.yaml extends data/sim_lio.yaml (`base:`): its own keys, and the base's
// everywhere else, the per-method overrides included.
TEST(OdometryConfig, CalibrationConfigExtendsTheSimConfig) {
  const OdometryConfig sim = LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  const OdometryConfig cal =
      LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio_calibration.yaml");
  EXPECT_EQ(cal.knots_per_scan, 2);
  EXPECT_TRUE(cal.imu_prediction);
  EXPECT_FALSE(sim.imu_prediction);
  EXPECT_DOUBLE_EQ(cal.accel_variance, 0.16);
  EXPECT_DOUBLE_EQ(cal.accel_loss_scale, 0.5);
  EXPECT_DOUBLE_EQ(cal.frontend.voxel_size, 0.5);
  EXPECT_DOUBLE_EQ(cal.frontend.initial_voxel_size, 0.5);
  EXPECT_EQ(cal.frontend.max_keypoints, 2400);
  EXPECT_TRUE(cal.calibration.estimate_time_offset);
  EXPECT_TRUE(cal.calibration.estimate_extrinsic);
  EXPECT_DOUBLE_EQ(cal.calibration.warmup_replay_s, 12.0);
  EXPECT_EQ(cal.calibration.warmup_replay_passes, 2);
  EXPECT_TRUE(cal.calibration.warmup_replay_hold);
  EXPECT_FALSE(cal.calibration.warmup_replay_freeze);
  // Untouched: the base's values (which differ from the struct's defaults).
  EXPECT_EQ(cal.qc, sim.qc);
  EXPECT_EQ(cal.alpha, sim.alpha);
  EXPECT_DOUBLE_EQ(cal.gyro_variance, sim.gyro_variance);
  EXPECT_EQ(cal.frontend.max_iterations, sim.frontend.max_iterations);
  EXPECT_DOUBLE_EQ(cal.frontend.point_noise_sigma, sim.frontend.point_noise_sigma);
  EXPECT_NE(sim.frontend.max_keypoints, LidarFrontendOptions().max_keypoints);
  // The base's overrides, and Singer-LIO's denser keypoints of the calibration overlay.
  EXPECT_EQ(sim.per_method.count(LioMethod::kSingerLio), 0u);
  EXPECT_EQ(cal.per_method.size(), sim.per_method.size() + 1);
  EXPECT_EQ(cal.ForMethod(LioMethod::kSingerLio).frontend.max_keypoints, 4800);
  ASSERT_FALSE(sim.per_method.empty());
  for (const auto& [method, override_config] : sim.per_method) {
    ASSERT_EQ(cal.per_method.count(method), 1u);
    EXPECT_EQ(cal.per_method.at(method)->frontend.max_iterations,
              override_config->frontend.max_iterations);
  }
}

// `base:` overlays mapping by mapping: a key inside a section replaces that key only, a list
// replaces the whole list; the path is relative to the extending file; bases chain.
TEST(OdometryConfig, BaseOverlaysKeyByKey) {
  WriteTemp("overlay_root.yaml",
            "gp:\n  qc: [1, 2, 3, 4, 5, 6]\nwindow:\n  knots: 3\n  threads: 2\n"
            "lidar_frontend:\n  max_keypoints: 500\n");
  WriteTemp("overlay_mid.yaml", "base: overlay_root.yaml\nwindow:\n  knots: 4\n");
  const OdometryConfig c = LoadOdometryConfig(
      WriteTemp("overlay_top.yaml", "base: overlay_mid.yaml\ngp:\n  qc: [7, 7, 7, 8, 8, 8]\n"));
  EXPECT_EQ(c.window_knots, 4);
  EXPECT_EQ(c.solver_threads, 2);
  EXPECT_EQ(c.frontend.max_keypoints, 500);
  EXPECT_DOUBLE_EQ(c.qc[0], 7);
  EXPECT_DOUBLE_EQ(c.qc[5], 8);
  const YAML::Node merged = LoadOdometryYaml(::testing::TempDir() + "/overlay_top.yaml");
  EXPECT_FALSE(merged["base"].IsDefined());
  EXPECT_EQ(merged["window"]["knots"].as<int>(), 4);
}

// Errors of an extending config name the file and line of the `base:` that led there, and
// errors inside the base name the base's own file and line.
TEST(OdometryConfig, BaseErrorsNameTheFiles) {
  const auto message = [](const std::string& path) {
    try {
      LoadOdometryConfig(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string missing =
      WriteTemp("base_missing.yaml", "window:\n  knots: 3\nbase: no_such_config.yaml\n");
  std::string m = message(missing);
  EXPECT_NE(m.find(missing + ":3: base:"), std::string::npos) << m;
  EXPECT_NE(m.find("no_such_config.yaml: cannot open"), std::string::npos) << m;
  WriteTemp("base_bad.yaml", "window:\n  knots: 3\n  knotz: 2\n");
  m = message(WriteTemp("base_bad_top.yaml", "base: base_bad.yaml\n"));
  EXPECT_NE(m.find("/base_bad.yaml:3: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find("window.knotz"), std::string::npos) << m;
  WriteTemp("base_cycle_a.yaml", "base: base_cycle_b.yaml\n");
  m = message(WriteTemp("base_cycle_b.yaml", "base: base_cycle_a.yaml\n"));
  EXPECT_NE(m.find("extend each other"), std::string::npos) << m;
  WriteTemp("base_plain.yaml", "window:\n  knots: 3\n");
  m = message(WriteTemp("base_device.yaml", "base: /dev/zero\n"));  // would never end
  EXPECT_NE(m.find("/dev/zero is not a regular file"), std::string::npos) << m;
  m = message(WriteTemp("base_folder.yaml", "base: .\n"));
  EXPECT_NE(m.find("is not a regular file"), std::string::npos) << m;
  // A list of bases is read in order: its first missing file is named.
  m = message(WriteTemp("base_list.yaml", "base: [base_plain.yaml, no_such_b.yaml]\n"));
  EXPECT_NE(m.find("no_such_b.yaml: cannot open"), std::string::npos) << m;
  m = message(WriteTemp("base_list_bad.yaml", "base: [base_plain.yaml, [x.yaml]]\n"));
  EXPECT_NE(m.find("must be the path"), std::string::npos) << m;
  // A key of the extending file still names the extending file.
  const std::string top_bad =
      WriteTemp("base_top_bad.yaml", "base: base_plain.yaml\nwindow:\n  overlap: 2x\n");
  m = message(top_bad);
  EXPECT_NE(m.find(top_bad + ":3"), std::string::npos) << m;
}

}  // namespace
}  // namespace ctlio::lio
