// The simulated worlds: determinism in the seed, the motion staying in free space, the guided
// motion's twist and IMU consistent with its pose, and returns lying on the geometry.
#include "ctlio/sim/worlds.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {
namespace {

const WorldKind kAllWorlds[] = {WorldKind::kBox,  WorldKind::kStreet, WorldKind::kCorridor,
                                WorldKind::kPark, WorldKind::kIndoor, WorldKind::kQuad,
                                WorldKind::kTown, WorldKind::kOffice};

// FNV-1a over every coordinate of every primitive and path point.
uint64_t WorldHash(const World& w) {
  uint64_t h = 1469598103934665603ULL;
  auto add = [&h](const double* p, size_t n) {
    const auto* b = reinterpret_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  for (const Box& b : w.scene.boxes) add(b.min.data(), 3), add(b.max.data(), 3);
  for (const Cylinder& c : w.scene.cylinders) add(c.base.data(), 3), add(&c.radius, 1);
  for (const Sphere& s : w.scene.spheres) add(s.centre.data(), 3), add(&s.radius, 1);
  for (const HeightField& f : w.scene.fields) add(f.z.data(), f.z.size());
  for (const Vec3& p : w.path.ControlPoints()) add(p.data(), 3);
  return h;
}

TEST(Worlds, EachWorldIsAPureFunctionOfItsSeed) {
  RoomConfig room;
  for (WorldKind kind : kAllWorlds) {
    WorldConfig c;
    c.kind = kind;
    const World a = BuildWorld(c, room), b = BuildWorld(c, room);
    EXPECT_EQ(WorldHash(a), WorldHash(b)) << WorldName(kind);
    EXPECT_EQ(ParseWorld(WorldName(kind)), kind);
    c.seed += 1;
    const World other = BuildWorld(c, room);
    // Box and corridor have no random part; the others change with the seed.
    const bool random = kind != WorldKind::kBox && kind != WorldKind::kCorridor;
    EXPECT_EQ(WorldHash(other) != WorldHash(a), random) << WorldName(kind);
    EXPECT_GT(a.path.Length(), 50.0);
  }
  EXPECT_THROW(ParseWorld("moon"), std::runtime_error);
}

TEST(Worlds, DocumentedSizes) {
  RoomConfig room;
  WorldConfig c;
  c.kind = WorldKind::kStreet;
  const World street = BuildWorld(c, room);
  const Box b = street.scene.Bounds();
  EXPECT_GT(b.max.x() - b.min.x(), 400.0);  // 400 m streets plus façades
  EXPECT_GT(street.scene.boxes.size(), 100u);
  EXPECT_GT(street.scene.cylinders.size(), 50u);
  EXPECT_GT(street.scene.spheres.size(), 20u);  // tree crowns
  c.kind = WorldKind::kCorridor;
  const World corridor = BuildWorld(c, room);
  // The corridor is 3 m wide: from its axis the walls are 1.5 m away on both sides.
  Vec3 p, dp, ddp;
  corridor.path.Evaluate(30.0, &p, &dp, &ddp);
  const Vec3 side = Vec3(-dp.y(), dp.x(), 0).normalized();
  const Vec3 o = p + Vec3(0, 0, 1.5);
  EXPECT_NEAR(corridor.scene.Cast(o, side, 100).t, 1.5, 1e-6);
  EXPECT_NEAR(corridor.scene.Cast(o, -side, 100).t, 1.5, 1e-6);
  EXPECT_NEAR(corridor.scene.Cast(o, Vec3(0, 0, 1), 100).t, 1.5, 1e-9);
}

// Sample the motion of a whole sequence: the sensor never inside a solid and never closer to a
// surface than `clearance` along 26 directions. Returns the distance travelled.
double ExpectInsideFreeSpace(const LidarInertialSim& sim, double duration, double clearance) {
  const Scene& scene = sim.world().scene;
  double travelled = 0.0;
  for (double t = 0.0; t <= duration; t += 0.05) {
    const Vec3 p = sim.WorldFromImu(t).translation();
    if (t > 0) travelled += (p - sim.WorldFromImu(t - 0.05).translation()).norm();
    EXPECT_FALSE(scene.Occupied(p))
        << "t = " << t << " p = " << p.transpose() << " floors " << scene.floors.size()
        << " ceilings " << scene.ceilings.size() << " fields " << scene.fields.size() << " boxes "
        << scene.boxes.size();
    if (scene.Occupied(p)) return travelled;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          if (x == 0 && y == 0 && z == 0) continue;
          const Vec3 d = Vec3(x, y, z).normalized();
          EXPECT_GT(scene.Cast(p, d, clearance).t, clearance)
              << WorldName(sim.config().world.kind) << " t = " << t << " p = " << p.transpose()
              << " d = " << d.transpose();
          if (scene.Cast(p, d, clearance).t <= clearance) return travelled;
        }
  }
  return travelled;
}

TEST(Worlds, MotionStaysInFreeSpaceForTwentySeconds) {
  const Regime regimes[] = {Regime::kSlow, Regime::kMedium, Regime::kFast, Regime::kWalking,
                            Regime::kVehicle};
  for (WorldKind kind : kAllWorlds) {
    for (Regime regime : regimes) {
      const bool vehicle = regime == Regime::kVehicle;
      // Two sequences of the new regimes, one of the body-rate regimes (test time).
      const bool guided_regime = regime == Regime::kWalking || vehicle;
      for (int index = 0; index < (guided_regime ? 2 : 1); ++index) {
        SimConfig c = ExperimentConfig(regime, index, kExperimentSeed, kind);
        c.duration_s = 20.0;
        c.integration_step_s = 1e-3;  // positions to ~1e-9 m; the test needs centimetres
        if (vehicle && (kind == WorldKind::kCorridor || kind == WorldKind::kIndoor ||
                        kind == WorldKind::kQuad || kind == WorldKind::kOffice)) {
          EXPECT_THROW(LidarInertialSim{c}, std::runtime_error);
          continue;
        }
        SCOPED_TRACE(std::string(WorldName(kind)) + " " + RegimeName(regime) + " " +
                     std::to_string(index));
        const LidarInertialSim sim(c);
        const double travelled = ExpectInsideFreeSpace(sim, c.duration_s, 0.2);
        // Guided sequences travel at least their carrier speed over the time after the ramp.
        if (c.motion.guided) {
          const GuideProfile& g = c.motion.guide;
          EXPECT_GT(travelled, 0.9 * (g.speed - g.speed_wave.amplitude) *
                                   (c.duration_s - c.motion.start_s - g.ramp_s));
        }
      }
    }
  }
}

// Pose derivative = body twist, second difference of position = specific force + gravity.
TEST(Worlds, GuidedTwistAndImuAreTheDerivativesOfThePose) {
  const std::pair<WorldKind, Regime> cases[] = {{WorldKind::kIndoor, Regime::kWalking},
                                                {WorldKind::kPark, Regime::kVehicle},
                                                {WorldKind::kStreet, Regime::kMedium},
                                                {WorldKind::kCorridor, Regime::kFast}};
  for (const auto& [kind, regime] : cases) {
    SimConfig c = ExperimentConfig(regime, 2, kExperimentSeed, kind);
    c.duration_s = 8.0;
    const LidarInertialSim sim(c);
    const Vec3 g_w(0, 0, -c.imu.gravity);
    for (double t : {0.1, 0.7, 2.345, 5.5, 7.9}) {
      SCOPED_TRACE(std::string(WorldName(kind)) + " " + RegimeName(regime) + " t " +
                   std::to_string(t));
      const double dt = 1e-5;
      const Vec6 xi =
          (sim.WorldFromImu(t - dt).Inverse() * sim.WorldFromImu(t + dt)).Log() / (2 * dt);
      EXPECT_LT((xi - sim.BodyTwist(t)).norm(), 2e-5 * (1 + sim.BodyTwist(t).norm()));
      const Vec6 rate = (sim.BodyTwist(t + dt) - sim.BodyTwist(t - dt)) / (2 * dt);
      EXPECT_LT((rate - sim.BodyTwistRate(t)).norm(), 1e-3 * (1 + rate.norm()));
      const double h = 1e-3;
      const Vec3 a_w =
          (sim.WorldFromImu(t + h).translation() - 2 * sim.WorldFromImu(t).translation() +
           sim.WorldFromImu(t - h).translation()) /
          (h * h);
      const Mat3 C = sim.WorldFromImu(t).rotation();
      EXPECT_LT((sim.TrueImu(t).accel - C.transpose() * (a_w - g_w)).norm(), 5e-3);
    }
  }
}

// Noise-free returns of every world lie on a surface: free just in front, solid just behind.
TEST(Worlds, ReturnsLieOnTheGeometry) {
  for (WorldKind kind : kAllWorlds) {
    SimConfig c = ExperimentConfig(Regime::kWalking, 0, kExperimentSeed, kind);
    c.duration_s = 1.0;
    c.lidar.range_noise = 0.0;
    c.lidar.beams = 32;
    c.lidar.firing_decimation = 9;
    const LidarInertialSim sim(c);
    const io::PointCloud cloud = sim.Scan(7);
    ASSERT_GT(cloud.size(), 1000u) << WorldName(kind);
    const Scene& scene = sim.world().scene;
    int checked = 0, in_medium = 0;
    for (size_t i = 0; i < cloud.size(); i += 3) {
      const SE3 T = sim.WorldFromLidar(sim.Seconds(cloud.times_ns[i]));
      const Vec3 p = T * cloud.points[i];
      const Vec3 d = (p - T.translation()).normalized();
      if (kind == WorldKind::kBox) continue;  // the room is checked in lidar_inertial_sim_test
      // Returns from foliage, grass and the ground's relief lie inside those (not on a solid).
      // (The relief lowers the ground in places: below the floor plane is solid.)
      if (scene.InMedium(p) || scene.OnMover(p, sim.Seconds(cloud.times_ns[i]))) {
        ++in_medium;  // (or on a walking person at the time of the ray)
      } else {
        EXPECT_FALSE(scene.Occupied(p - 1e-6 * d)) << WorldName(kind) << " " << i;
        EXPECT_TRUE(scene.Occupied(p + 1e-6 * d))
            << WorldName(kind) << " " << i << " p " << p.transpose() << " d " << d.transpose();
      }
      ++checked;
    }
    if (kind != WorldKind::kBox) EXPECT_GT(checked, 300);
    // The worlds of solids only have no media; the outdoor realistic ones return from foliage,
    // grass and relief (the office's only medium is a few plants).
    if (kind == WorldKind::kOffice) continue;
    if (kind == WorldKind::kQuad || kind == WorldKind::kTown) {
      EXPECT_GT(in_medium, checked / 50) << WorldName(kind);
    } else {
      EXPECT_EQ(in_medium, 0) << WorldName(kind);
    }
  }
}

}  // namespace
}  // namespace ctlio::sim
