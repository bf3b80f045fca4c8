// The default simulator output (no --sensor) must not change: Table II of the paper is computed
// from it. The checksums below were computed from the simulator before the sensor models
// (sensor_models.h) were added; a scan's points, times and rings are hashed bit for bit.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"

namespace ctlio::sim {
namespace {

// FNV-1a over the bytes of every coordinate, time and ring, in order.
uint64_t Checksum(const io::PointCloud& cloud) {
  uint64_t h = 1469598103934665603ULL;
  auto add = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  for (size_t i = 0; i < cloud.size(); ++i) {
    add(cloud.points[i].data(), 3 * sizeof(double));
    add(&cloud.times_ns[i], sizeof(int64_t));
    add(&cloud.ring[i], sizeof(uint16_t));
  }
  return h;
}

TEST(DefaultOutput, TableTwoScanUnchanged) {
  SimConfig c = ExperimentConfig(Regime::kFast, 3);
  c.duration_s = 1.0;
  c.lidar.firing_decimation = 8;
  const LidarInertialSim sim(c);
  const io::PointCloud scan = sim.Scan(4);
  EXPECT_EQ(scan.size(), 28800u);
  EXPECT_EQ(Checksum(scan), 9273704951039583268ULL);
}

// The preset's sensors, IMU and extrinsic in the world it was pinned in (the park: the preset now
// walks the quad world, a deliberate change of its world, not of its sensors).
TEST(DefaultOutput, NewerCollegePresetScanUnchanged) {
  SimOverrides o;
  o.world = WorldKind::kPark;
  o.duration_s = 1.0;
  o.firing_decimation = 4;
  o.sensor_effects = "off";  // the unit effects (sensor_effects.h) are a later, deliberate addition
  const LidarInertialSim sim(PresetConfig(Preset::kNewerCollege, 1, kExperimentSeed, o));
  const io::PointCloud scan = sim.Scan(2);
  EXPECT_EQ(scan.size(), 8787u);
  EXPECT_EQ(Checksum(scan), 7108849754448676133ULL);
}

}  // namespace
}  // namespace ctlio::sim
