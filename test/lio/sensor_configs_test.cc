// The shipped per-sensor configs (data/sensors/<sensor>.yaml): one per simulator sensor model,
// each loads through its base, carries its sensor's IMU rate and a noise no lower than its own,
// the driver's accelerometer unit, and an extrinsic exactly where the device fixes one (Ouster,
// Livox): never for an external IMU (Velodyne, Hesai), whose recording's /tf_static a config
// extrinsic would silently override.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "common/test_paths.h"
#include "ctlio/sim/sensor_models.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {
namespace {

const std::string kDir = ctlio::testing::SourceDir() + "/data/sensors/";

TEST(SensorConfigs, OnePerModelWithItsImuAndExtrinsic) {
  EXPECT_FALSE(LoadOdometryYaml(kDir + "base.yaml")["extrinsic"].IsDefined());
  for (const sim::SensorModel& m : sim::SensorModels()) {
    SCOPED_TRACE(m.name);
    const std::string path = kDir + m.name + ".yaml";
    ASSERT_TRUE(std::filesystem::is_regular_file(path));
    const OdometryConfig c = LoadOdometryConfig(path);
    EXPECT_EQ(c.imu_rate_hint, m.imu_rate_hz);
    // The baseline's σ: never below the device's (the files inflate it for preintegration and
    // gait errors, measured in docs/experiments/sensors.md).
    EXPECT_GE(c.input_accel_sigma, m.accel_noise);
    EXPECT_GE(c.input_gyro_sigma, m.gyro_noise);
    EXPECT_LE(c.frontend.max_range, m.lidar.max_range);
    // The bag readers' accelerometer unit is the driver's (Livox: g), so that the file alone
    // reads the device's bags (input.accel_scale; no --imu_accel_scale).
    EXPECT_EQ(c.input.accel_scale, m.driver.accel_unit);
    const bool built_in_imu =
        m.driver.format != io::PointFormat::kVelodyne && m.driver.format != io::PointFormat::kHesai;
    EXPECT_EQ(LoadOdometryYaml(path)["extrinsic"].IsDefined(), built_in_imu);
    if (built_in_imu) {
      EXPECT_LT((c.T_imu_lidar.Matrix() - m.imu_from_lidar.Matrix()).norm(), 1e-12);
    }
  }
}

}  // namespace
}  // namespace ctlio::lio
