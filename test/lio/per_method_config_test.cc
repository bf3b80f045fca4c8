// Per-method overrides in the odometry configuration (`per_method`): an override replaces only
// its keys and only for its method, applies onto the complete base whatever the key order, and
// keeps the file's rules (unknown keys and bad values name file and line; method and extrinsic
// are not per-method settings).
#include <gtest/gtest.h>

#include <fstream>

#include "common/test_paths.h"
#include "common/write_temp.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {
namespace {

using ctlio::testing::WriteTemp;

// Expects LoadOdometryConfig(text) to throw naming the file, `line` and `needle`.
void ExpectError(const std::string& name, const std::string& text, int line,
                 const std::string& needle) {
  const std::string path = WriteTemp(name, text);
  try {
    LoadOdometryConfig(path);
    ADD_FAILURE() << "expected an error for:\n" << text;
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ":" + std::to_string(line)), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

TEST(PerMethodConfig, OverrideReplacesOnlyItsKeysForItsMethod) {
  // The override comes first in the file: it still applies onto the complete base.
  const OdometryConfig c = LoadOdometryConfig(WriteTemp("pm.yaml",
                                                        "per_method:\n"
                                                        "  imu_input:\n"
                                                        "    lidar_frontend:\n"
                                                        "      max_iterations: 7\n"
                                                        "    imu:\n"
                                                        "      input_accel_sigma: 0.3\n"
                                                        "method: singer_lio\n"
                                                        "imu:\n"
                                                        "  input_accel_sigma: 0.1\n"
                                                        "  gyro_variance: 0.002\n"
                                                        "lidar_frontend:\n"
                                                        "  max_iterations: 2\n"
                                                        "  max_keypoints: 400\n"));
  EXPECT_EQ(c.method, LioMethod::kSingerLio);
  const OdometryConfig singer = c.ForMethod(LioMethod::kSingerLio);
  EXPECT_EQ(singer.method, LioMethod::kSingerLio);
  EXPECT_EQ(singer.frontend.max_iterations, 2);
  EXPECT_DOUBLE_EQ(singer.input_accel_sigma, 0.1);
  const OdometryConfig input = c.ForMethod(LioMethod::kImuInput);
  EXPECT_EQ(input.method, LioMethod::kImuInput);
  EXPECT_EQ(input.frontend.max_iterations, 7);
  EXPECT_DOUBLE_EQ(input.input_accel_sigma, 0.3);
  // Keys the override does not name keep the base's values (not the defaults).
  EXPECT_EQ(input.frontend.max_keypoints, 400);
  EXPECT_DOUBLE_EQ(input.gyro_variance, 0.002);
  EXPECT_TRUE(input.per_method.empty());
  // A method without an override runs the base.
  const OdometryConfig gyro = c.ForMethod(LioMethod::kLidarGyro);
  EXPECT_EQ(gyro.method, LioMethod::kLidarGyro);
  EXPECT_EQ(gyro.frontend.max_iterations, 2);
}

TEST(PerMethodConfig, ErrorsNameFileAndLine) {
  ExpectError("pm_key.yaml", "per_method:\n  imu_input:\n    imu:\n      input_acel_sigma: 1\n", 4,
              "per_method.imu_input.imu.input_acel_sigma");
  ExpectError("pm_fe.yaml", "per_method:\n  singer_lio:\n    lidar_frontend:\n      max_iter: 1\n",
              4, "max_iter");
  ExpectError("pm_method.yaml", "per_method:\n  kalman:\n    imu: {}\n", 2, "kalman");
  ExpectError("pm_ext.yaml",
              "per_method:\n  imu_input:\n    extrinsic:\n      xyz_rpy: [0,0,0,0,0,0]\n", 3,
              "cannot be set per method");
  ExpectError("pm_nest.yaml", "per_method:\n  imu_input:\n    method: singer_lio\n", 3,
              "cannot be set per method");
  ExpectError("pm_type.yaml", "per_method:\n  imu_input:\n    window:\n      knots: many\n", 4,
              "per_method.imu_input.window.knots");
  // A value that parses but is invalid for the method it overrides.
  EXPECT_THROW(LoadOdometryConfig(
                   WriteTemp("pm_bad.yaml", "per_method:\n  imu_input:\n    window: {knots: 1}\n")),
               std::runtime_error);
  EXPECT_THROW(LoadOdometryConfig(WriteTemp("pm_seq.yaml", "per_method: [imu_input]\n")),
               std::runtime_error);
}

// The covariance-only lidar variance scale (issue 43): per method, the others keep 1 (the window
// as solved); a scale that is not positive is an error naming the key.
TEST(PerMethodConfig, PoseCovarianceLidarScaleIsPerMethodAndPositive) {
  const OdometryConfig c =
      LoadOdometryConfig(WriteTemp("pcl.yaml",
                                   "per_method:\n"
                                   "  singer_lio: {window: {pose_covariance_lidar_scale: 0.1}}\n"));
  EXPECT_DOUBLE_EQ(c.pose_covariance_lidar_scale, 1.0);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kSingerLio).pose_covariance_lidar_scale, 0.1);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).pose_covariance_lidar_scale, 1.0);
  for (const char* bad : {"0", "-2", ".nan"}) {
    const std::string path = WriteTemp(
        "pcl_bad.yaml", std::string("window:\n  pose_covariance_lidar_scale: ") + bad + "\n");
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << "expected an error for " << bad;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("pose_covariance_lidar_scale"), std::string::npos)
          << e.what();
    }
  }
}

// The lidar floor of the pose covariance: per method (data/sim_lio.yaml sets it for the
// baseline only); it and the map's σ negative, absurd or NaN: an error naming the key.
TEST(PerMethodConfig, PoseCovarianceLidarFloorIsPerMethodAndNonNegative) {
  const OdometryConfig c = LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  EXPECT_EQ(c.ForMethod(LioMethod::kSingerLio).pose_covariance_lidar_floor_m, 0.0);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).pose_covariance_lidar_floor_m, 0.002);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).pose_covariance_lidar_floor_rad, 0.0002);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).pose_covariance_lidar_scale, 0.16);
  // The map's error as built: Singer-LIO's on the VLP-16 (data/sensors/vlp16.yaml), the
  // baseline's on the Newer College-like preset (data/newer_college_lio.yaml).
  EXPECT_EQ(c.ForMethod(LioMethod::kSingerLio).pose_covariance_map_growth, 0.0);
  const OdometryConfig v =
      LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sensors/vlp16.yaml");
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kSingerLio).pose_covariance_map_growth, 1.0);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kSingerLio).pose_covariance_map_sigma_rad, 0.0003);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kSingerLio).pose_covariance_map_sigma_m, 0.0);
  EXPECT_EQ(v.ForMethod(LioMethod::kImuInput).pose_covariance_map_growth, 0.0);
  // The model's misfit (misfit_covariance.h): Singer-LIO's on the VLP-16, off by default.
  EXPECT_TRUE(v.ForMethod(LioMethod::kSingerLio).pose_covariance_misfit);
  EXPECT_FALSE(v.ForMethod(LioMethod::kImuInput).pose_covariance_misfit);
  EXPECT_TRUE(c.ForMethod(LioMethod::kSingerLio).pose_covariance_misfit);
  EXPECT_FALSE(OdometryConfig().pose_covariance_misfit);
  // The Cauchy scale 0.05 is both methods' (vlp16.yaml's per_method); lidar_only keeps the base's.
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kSingerLio).frontend.loss_scale, 0.05);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kImuInput).frontend.loss_scale, 0.05);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kLidarOnly).frontend.loss_scale, 0.2);
  // The line-neighbourhood plane fit is both methods' (vlp16.yaml's lidar_frontend).
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kSingerLio).frontend.line_neighbourhood_ratio, 0.3);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kImuInput).frontend.line_neighbourhood_ratio, 0.3);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kImuInput).pose_covariance_map_sigma_rad, 0.0005);
  EXPECT_DOUBLE_EQ(v.ForMethod(LioMethod::kImuInput).pose_covariance_map_sigma_m, 0.002);
  const OdometryConfig nc =
      LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/newer_college_lio.yaml");
  EXPECT_DOUBLE_EQ(nc.ForMethod(LioMethod::kImuInput).pose_covariance_map_growth, 1.0);
  EXPECT_EQ(nc.ForMethod(LioMethod::kSingerLio).pose_covariance_map_growth, 0.0);
  for (const char* key : {"pose_covariance_lidar_floor_m", "pose_covariance_lidar_floor_rad",
                          "pose_covariance_map_sigma_m", "pose_covariance_map_sigma_rad",
                          "pose_covariance_map_growth"}) {
    for (const char* bad : {"-0.001", "1e9", ".nan"}) {
      const std::string path =
          WriteTemp("floor_bad.yaml", std::string("window:\n  ") + key + ": " + bad + "\n");
      try {
        LoadOdometryConfig(path);
        ADD_FAILURE() << "expected an error for " << key << " " << bad;
      } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      }
    }
  }
}

// The adaptive covariance's lidar inflation: per method as the data configs set it; below 1
// (it inflates), absurd or NaN is an error naming the key.
TEST(PerMethodConfig, PoseCovarianceLidarNeffIsPerMethodAndAtLeastOne) {
  const OdometryConfig c = LoadOdometryConfig(
      WriteTemp("neff.yaml",
                "window: {pose_covariance_adaptive: true, pose_covariance_lidar_neff: 10}\n"
                "per_method:\n"
                "  imu_input: {window: {pose_covariance_lidar_neff: 40}}\n"));
  EXPECT_TRUE(c.pose_covariance_adaptive);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kSingerLio).pose_covariance_lidar_neff, 10.0);
  EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).pose_covariance_lidar_neff, 40.0);
  for (const char* bad : {"0.5", "-2", "1e9", ".nan"}) {
    const std::string path = WriteTemp(
        "neff_bad.yaml", std::string("window:\n  pose_covariance_lidar_neff: ") + bad + "\n");
    try {
      LoadOdometryConfig(path);
      ADD_FAILURE() << "expected an error for " << bad;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("pose_covariance_lidar_neff"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace ctlio::lio
