// Simulator presets (presets.h): the Newer College preset sets the OS1-64 geometry, the 100 Hz
// IMU, the published extrinsic, the park world and the walking regime; explicit settings win over
// it; a short preset sequence written in the Newer College layout reads back consistent with the
// published extrinsic the reader assumes.
#include "ctlio/sim/presets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/temp_dir.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {
namespace {

void ExpectSameSE3(const SE3& a, const SE3& b, double tol) {
  EXPECT_LE((a.rotation() - b.rotation()).norm(), tol);
  EXPECT_LE((a.translation() - b.translation()).norm(), tol);
}

TEST(Presets, ParseAndName) {
  EXPECT_EQ(ParsePreset(""), Preset::kNone);
  EXPECT_EQ(ParsePreset("none"), Preset::kNone);
  EXPECT_EQ(ParsePreset("newer_college"), Preset::kNewerCollege);
  EXPECT_STREQ(PresetName(Preset::kNewerCollege), "newer_college");
  EXPECT_THROW(ParsePreset("newer-college"), std::runtime_error);
}

TEST(Presets, NewerCollegeSetsWhatItSays) {
  const SimConfig c = PresetConfig(Preset::kNewerCollege, 3);
  EXPECT_EQ(c.lidar.beams, 64);
  EXPECT_EQ(c.lidar.firings_per_revolution, 1024);
  EXPECT_DOUBLE_EQ(c.lidar.rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(c.lidar.max_elevation_deg - c.lidar.min_elevation_deg, 33.2);
  EXPECT_DOUBLE_EQ(c.lidar.max_elevation_deg, 16.6);
  EXPECT_EQ(c.lidar.firing_decimation, 1);
  EXPECT_GT(c.lidar.range_noise_per_m, 0.0);
  EXPECT_DOUBLE_EQ(c.imu.rate_hz, 100.0);
  EXPECT_GT(c.imu.accel_bias_walk, 0.0);
  EXPECT_GT(c.imu.gyro_bias_walk, 0.0);
  EXPECT_FALSE(c.imu.body_centric);
  ExpectSameSE3(c.imu_from_lidar, io::NewerCollegeImuFromLidar(), 0.0);
  EXPECT_EQ(c.imu_from_lidar.rotation().diagonal(), Vec3(-1, -1, 1));
  // The college quad since the realistic worlds (it was the park before).
  EXPECT_EQ(c.world.kind, WorldKind::kQuad);
  EXPECT_GE(c.duration_s, 60.0);
  EXPECT_LE(c.duration_s, 300.0);
  // The walking regime: guided at 1.2–1.6 m/s with head turns (same draw as ExperimentConfig).
  const SimConfig walking =
      ExperimentConfig(Regime::kWalking, 3, kExperimentSeed, WorldKind::kPark);
  EXPECT_TRUE(c.motion.guided);
  EXPECT_EQ(c.motion.guide.speed, walking.motion.guide.speed);
  EXPECT_GE(c.motion.guide.speed, 1.2);
  EXPECT_LE(c.motion.guide.speed, 1.6);
  EXPECT_GT(c.motion.guide.yaw_slow.amplitude, 0.0);
  EXPECT_EQ(c.seed, walking.seed);
  // Without a preset: the Table II simulator.
  const SimConfig none = PresetConfig(Preset::kNone, 3);
  EXPECT_EQ(none.lidar.beams, 128);
  EXPECT_DOUBLE_EQ(none.imu.rate_hz, 200.0);
  EXPECT_EQ(none.world.kind, WorldKind::kBox);
  EXPECT_FALSE(none.motion.guided);  // the fast regime in the box room
}

TEST(Presets, ExplicitSettingsOverrideThePreset) {
  SimOverrides o;
  o.beams = 16;
  o.duration_s = 2.5;
  o.world = WorldKind::kStreet;
  o.regime = Regime::kVehicle;
  o.firing_decimation = 4;
  o.accel_bias_walk = 0.0;
  o.newer_college_extrinsic = false;
  const SimConfig c = PresetConfig(Preset::kNewerCollege, 1, kExperimentSeed, o);
  EXPECT_EQ(c.lidar.beams, 16);
  EXPECT_DOUBLE_EQ(c.duration_s, 2.5);
  EXPECT_EQ(c.world.kind, WorldKind::kStreet);
  EXPECT_GE(c.motion.guide.speed, 8.0);  // vehicle
  EXPECT_EQ(c.lidar.firing_decimation, 4);
  EXPECT_EQ(c.imu.accel_bias_walk, 0.0);
  ExpectSameSE3(c.imu_from_lidar, SE3(), 0.0);
  // What was not overridden keeps the preset's value.
  EXPECT_EQ(c.lidar.firings_per_revolution, 1024);
  EXPECT_DOUBLE_EQ(c.imu.rate_hz, 100.0);
  EXPECT_GT(c.imu.gyro_bias_walk, 0.0);
  EXPECT_DOUBLE_EQ(c.lidar.rate_hz, 10.0);
}

TEST(Presets, SensorModelsCarryTheirUnitEffectsOnlyInTheRealisticWorlds) {
  SimOverrides o;
  o.sensor = "vlp16";
  o.world = WorldKind::kQuad;
  EXPECT_EQ(PresetSensorEffects(Preset::kNone, o), "velodyne");
  EXPECT_GT(
      PresetConfig(Preset::kNone, 0, kExperimentSeed, o).lidar.effects.mixed_pixel_probability,
      0.0);
  o.world = WorldKind::kTown;
  EXPECT_EQ(PresetSensorEffects(Preset::kNone, o), "velodyne");
  // Table II's box and the older worlds stay ideal.
  for (WorldKind w : {WorldKind::kBox, WorldKind::kStreet, WorldKind::kPark}) {
    o.world = w;
    EXPECT_EQ(PresetSensorEffects(Preset::kNone, o), "off");
    EXPECT_EQ(
        PresetConfig(Preset::kNone, 0, kExperimentSeed, o).lidar.effects.mixed_pixel_probability,
        0.0);
  }
  // No sensor model: no unit to model, whatever the world; an explicit choice always wins.
  SimOverrides bare;
  bare.world = WorldKind::kOffice;
  EXPECT_EQ(PresetSensorEffects(Preset::kNone, bare), "off");
  bare.sensor_effects = "hesai";
  EXPECT_EQ(PresetSensorEffects(Preset::kNone, bare), "hesai");
  o.world = WorldKind::kQuad;
  o.sensor_effects = "off";
  EXPECT_EQ(PresetSensorEffects(Preset::kNone, o), "off");
}

TEST(Presets, LidarRateSetsTheScanRate) {
  SimOverrides o;
  o.lidar_rate_hz = 20.0;
  o.duration_s = 1.0;
  o.beams = 4;
  o.firing_decimation = 16;
  const SimConfig c = PresetConfig(Preset::kNone, 0, kExperimentSeed, o);
  EXPECT_DOUBLE_EQ(c.lidar.rate_hz, 20.0);
  // Twice the scans of a 10 Hz sensor, each half as long.
  SimulatedSource source(c);
  io::ScanFrame frame;
  int scans = 0;
  while (source.Next(&frame)) {
    ++scans;
    EXPECT_NEAR(1e-9 * static_cast<double>(frame.end_ns - frame.start_ns), 0.05, 0.005);
  }
  EXPECT_EQ(scans, 20);
  for (const double bad : {0.0, -5.0, 101.0}) {
    o.lidar_rate_hz = bad;
    EXPECT_THROW(PresetConfig(Preset::kNone, 0, kExperimentSeed, o), std::runtime_error) << bad;
  }
}

TEST(Presets, NewerCollegeLayoutReadsBackWithThePublishedExtrinsic) {
  SimOverrides o;
  o.duration_s = 0.45;
  o.firing_decimation = 16;
  const SimConfig c = PresetConfig(Preset::kNewerCollege, 100, kExperimentSeed, o);
  SimulatedSource source(c, "preset");
  const auto dir = testing::FreshTempDir("presets_nc");
  const size_t written = io::WriteNewerCollege(source, dir.string());
  ASSERT_GE(written, 4u);

  io::NewerCollegeReader reader(dir.string());
  ASSERT_EQ(reader.NumScans(), written);
  ExpectSameSE3(reader.ImuFromLidar(), c.imu_from_lidar, 0.0);
  // 100 Hz IMU.
  const auto& imu = reader.imu();
  ASSERT_GE(imu.size(), 40u);
  EXPECT_NEAR(1e-9 * double(imu[1].t_ns - imu[0].t_ns), 0.01, 1e-6);
  // Ground truth read back as T_world_lidar is the simulator's T_wb·T_bl with the published T_bl:
  // the reader's extrinsic maps it onto the simulated IMU pose.
  const auto truth = reader.GroundTruth();
  ASSERT_TRUE(truth.has_value());
  ASSERT_FALSE(truth->empty());
  const LidarInertialSim& sim = source.simulator();
  for (const auto& p : *truth) {
    const SE3 T_wb = p.pose * reader.ImuFromLidar().Inverse();
    ExpectSameSE3(T_wb, sim.WorldFromImu(sim.Seconds(p.t_ns)), 1e-5);
  }
  // OS1-64 geometry: 64 rings, ≤ 1024/16 firings per scan, returns beyond 0.8 m.
  io::ScanFrame frame;
  ASSERT_TRUE(reader.Next(&frame));
  ASSERT_FALSE(frame.cloud.ring.empty());
  EXPECT_LE(*std::max_element(frame.cloud.ring.begin(), frame.cloud.ring.end()), 63);
  EXPECT_LE(frame.cloud.size(), size_t(64 * 1024 / 16));
  EXPECT_GT(frame.cloud.size(), size_t(64 * 1024 / 16 / 4));  // the park: ground all around
  for (const Vec3& q : frame.cloud.points) EXPECT_GE(q.norm(), 0.8 - 0.1);
}

}  // namespace
}  // namespace ctlio::sim
