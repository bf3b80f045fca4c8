// The shipped per-sensor configs (data/sensors/<sensor>.yaml): one per simulator sensor model,
// each loads through its base, carries its sensor's IMU rate and a noise no lower than its own,
// the driver's accelerometer unit, and an extrinsic exactly where the device fixes one (Ouster,
// Livox): never for an external IMU (Velodyne, Hesai), whose recording's /tf_static a config
// extrinsic would silently override; where a file weighs planes by their thickness, foliage
// weighs less than a wall; each estimator's Cauchy scale is its sensor's, set without losing the
// base's per-method budget.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <random>

#include "common/test_paths.h"
#include "ctlio/sim/sensor_models.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"

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

// lidar_frontend.plane_thickness_noise where a file sets it: a wall seen with the sensor's range
// noise keeps at least 90 % of its residual's weight, a crown's foliage (returns scattered
// through its depth: points filling a 2 m ball) gets less than half a wall's.
TEST(SensorConfigs, ThicknessWeightTellsFoliageFromAWall) {
  int files_with_it = 0;
  for (const sim::SensorModel& m : sim::SensorModels()) {
    SCOPED_TRACE(m.name);
    const OdometryConfig c = LoadOdometryConfig(kDir + m.name + ".yaml");
    const LidarFrontendOptions o = c.frontend;
    if (o.plane_thickness_noise == 0.0) continue;
    ++files_with_it;
    // Tuned for the two IMU methods; the lidar-only registrations keep every plane at full weight
    // (base.yaml's per_method), beside the baseline's own budget there.
    EXPECT_EQ(c.ForMethod(LioMethod::kImuInput).frontend.plane_thickness_noise,
              o.plane_thickness_noise);
    EXPECT_EQ(c.ForMethod(LioMethod::kImuInput).frontend.max_iterations, 4);
    EXPECT_EQ(c.ForMethod(LioMethod::kLidarOnly).frontend.plane_thickness_noise, 0.0);
    EXPECT_EQ(c.ForMethod(LioMethod::kLidarGyro).frontend.plane_thickness_noise, 0.0);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, m.lidar.range_noise);
    VoxelMap wall(LidarFrontend::MapOptions(o));
    for (double y = -3; y <= 3; y += 0.1)
      for (double z = 0; z <= 6; z += 0.1) wall.Insert(Vec3(20.0 + noise(rng), y, z));
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    VoxelMap crown(LidarFrontend::MapOptions(o));
    for (int k = 0; k < 4000; ++k) {
      const Vec3 d(u(rng), u(rng), u(rng));
      if (d.norm() <= 2.0) crown.Insert(Vec3(20.0, 0.0, 4.0) + d);
    }
    const Vec3 q(20.0, 0.3, 2.0);
    PlaneAssociation a;
    double t_wall = 0.0, t_crown = 0.0;
    ASSERT_TRUE(PlaneAssociator(wall, o).Associate(q, q, &a, &t_wall));
    ASSERT_TRUE(PlaneAssociator(crown, o).Associate(q, Vec3(20.0, 0.0, 4.0), &a, &t_crown));
    const double sigma = PointNoiseSigma(o, q);
    EXPECT_GT(sigma / PointNoiseSigma(o, q, t_wall), 0.9);
    EXPECT_LT(sigma / PointNoiseSigma(o, q, t_crown), 0.5 * sigma / PointNoiseSigma(o, q, t_wall));
  }
  EXPECT_GE(files_with_it, 1);
}

// Each file's per-method Cauchy scale (chosen per sensor and estimator on the tuning cells,
// docs/experiments/scoreboard.md, "Every sensor's Cauchy scale") merges into base.yaml's
// per_method block: the baseline keeps its registration budget and cubic IMU reading, and the
// lidar-only registrations keep the file's own scale.
TEST(SensorConfigs, EachEstimatorHasItsSensorsCauchyScale) {
  struct Scale {
    const char* sensor;
    double singer_lio, imu_input, lidar_only;
  };
  const Scale scales[] = {{"os0_128", 0.1, 0.1, 0.2},  {"os1_64", 0.05, 0.05, 0.2},
                          {"os1_128", 0.05, 0.1, 0.2}, {"vlp16", 0.05, 0.05, 0.2},
                          {"hdl32e", 0.05, 0.05, 0.1}, {"pandar_xt32", 0.1, 0.05, 0.2},
                          {"mid360", 0.05, 0.1, 0.2},  {"avia", 0.05, 0.05, 0.2}};
  ASSERT_EQ(std::size(scales), sim::SensorModels().size());
  for (const Scale& s : scales) {
    SCOPED_TRACE(s.sensor);
    const OdometryConfig c = LoadOdometryConfig(kDir + s.sensor + ".yaml");
    EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kSingerLio).frontend.loss_scale, s.singer_lio);
    EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kImuInput).frontend.loss_scale, s.imu_input);
    EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kLidarOnly).frontend.loss_scale, s.lidar_only);
    EXPECT_DOUBLE_EQ(c.ForMethod(LioMethod::kLidarGyro).frontend.loss_scale, s.lidar_only);
    const OdometryConfig b = c.ForMethod(LioMethod::kImuInput);
    EXPECT_EQ(b.frontend.max_iterations, 4);
    EXPECT_EQ(b.frontend.max_keypoints, 800);
    EXPECT_EQ(b.input_substeps, 4);
    EXPECT_EQ(b.input_interpolation, "cubic");
  }
}

}  // namespace
}  // namespace ctlio::lio
