// The realistic worlds' content (apps/sim world_content.h, geometry.h's media, ground cover,
// relief and glass): the worlds of solids unchanged, determinism in the seeds, the media's
// physics, and the geometry statistic of the quad and the town near the real sweeps'.
#include <gtest/gtest.h>

#include <cmath>

#include "ctlio/sim/lidar_inertial_sim.h"
namespace ctlio::sim {
namespace {
// FNV-1a over every point, time and ring of two scans of a world.
uint64_t ScanHash(WorldKind kind, Regime regime, double max_incidence_deg = 90.0) {
  SimConfig c = ExperimentConfig(regime, 1, kExperimentSeed, kind);
  c.duration_s = 2.0;
  c.lidar.beams = 32;
  c.lidar.firing_decimation = 5;
  c.lidar.max_incidence_deg = max_incidence_deg;
  c.integration_step_s = 1e-3;
  const LidarInertialSim sim(c);
  uint64_t h = 1469598103934665603ULL;
  auto add = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  for (size_t k : {3, 17}) {
    const io::PointCloud cl = sim.Scan(k);
    for (size_t i = 0; i < cl.size(); ++i) {
      add(cl.points[i].data(), 24);
      add(&cl.times_ns[i], 8);
      add(&cl.ring[i], 2);
    }
  }
  return h;
}
// The worlds that existed before the realistic content give the same scans bit for bit: the
// hashes were printed by this test built against the simulator of the commit before it (2f0373d),
// the box with the incidence gate on (which casts through the Scene instead of the room).
// (LidarInertialSim.BoxWorldReproducesThePreviousSimulatorBitForBit checks the default box.)
TEST(WorldContent, WorldsOfSolidsAreUnchanged) {
  EXPECT_EQ(ScanHash(WorldKind::kBox, Regime::kMedium, 80.0), 0x38d33b7be1bb8f11ULL);
  EXPECT_EQ(ScanHash(WorldKind::kStreet, Regime::kVehicle), 0xd392db32f866b7d2ULL);
  EXPECT_EQ(ScanHash(WorldKind::kCorridor, Regime::kWalking), 0x7f5c83f3853dd799ULL);
  EXPECT_EQ(ScanHash(WorldKind::kPark, Regime::kWalking), 0x426ef45647a03166ULL);
  EXPECT_EQ(ScanHash(WorldKind::kIndoor, Regime::kWalking), 0x031b8b58c89fd56bULL);
}

}  // namespace
}  // namespace ctlio::sim
