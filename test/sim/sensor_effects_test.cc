// Effects of a real lidar unit (sensor_effects.h, LidarConfig): each one does what LidarConfig
// says, is a deterministic function of the seeds (the unit's fixed errors of `unit_seed` alone),
// and is off unless asked for (the default simulator and the presets without effects unchanged).
#include "ctlio/sim/sensor_effects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "ctlio/sim/presets.h"

namespace ctlio::sim {
namespace {

// The box room, medium motion, 16 beams, every 8th firing, no range noise: a return's range is
// the true range plus exactly the effect under test.
SimConfig Quiet(WorldKind world = WorldKind::kBox, Regime regime = Regime::kMedium) {
  SimConfig c = ExperimentConfig(regime, 1, kExperimentSeed, world);
  c.duration_s = 2.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  c.lidar.range_noise = 0.0;
  return c;
}

using RayKey = std::pair<int64_t, uint16_t>;  // (firing time, ring): one ray
std::map<RayKey, Vec3> ByRay(const io::PointCloud& c) {
  std::map<RayKey, Vec3> m;
  for (size_t i = 0; i < c.size(); ++i) m[{c.times_ns[i], c.ring[i]}] = c.points[i];
  return m;
}

// The surface hit by the ray of a reported point (nominal direction = true one without angle
// errors): its range and |cos| of the incidence angle.
std::pair<double, double> TrueHit(const LidarInertialSim& sim, int64_t t_ns, const Vec3& p) {
  const SE3 T = sim.WorldFromLidar(sim.Seconds(t_ns));
  const Vec3 d = T.rotation() * p.normalized();
  const RayHit h = sim.world().scene.Cast(T.translation(), d, 500.0, sim.Seconds(t_ns));
  return {h.t, std::abs(h.normal.dot(d))};
}

bool SameScan(const io::PointCloud& a, const io::PointCloud& b) {
  return a.points == b.points && a.times_ns == b.times_ns && a.ring == b.ring;
}

TEST(SensorEffects, RangeOffsetIsFixedPerBeamAndPerUnit) {
  SimConfig c = Quiet();
  const LidarInertialSim ideal(c);
  c.lidar.unit_seed = 7;
  c.lidar.effects.range_offset_sigma = 0.05;
  const LidarInertialSim unit(c);
  const io::PointCloud a = ideal.Scan(3), b = unit.Scan(3);
  ASSERT_EQ(a.size(), b.size());
  std::map<uint16_t, double> offset;  // per ring, from its first point
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = b.points[i].norm() - a.points[i].norm();
    auto [it, first] = offset.emplace(b.ring[i], d);
    EXPECT_NEAR(d, it->second, 1e-9) << "ring " << b.ring[i];
  }
  ASSERT_EQ(offset.size(), 16u);
  double sq = 0.0;
  for (const auto& [ring, d] : offset) sq += d * d;
  EXPECT_GT(std::sqrt(sq / 16.0), 0.02);  // σ = 5 cm over 16 beams
  EXPECT_LT(std::sqrt(sq / 16.0), 0.09);
  // Another sequence (other noise seed and motion) of the same unit: the same offsets.
  SimConfig other = ExperimentConfig(Regime::kFast, 4);
  other.duration_s = 2.0;
  other.lidar = c.lidar;
  const LidarInertialSim same_unit(other);
  other.lidar.effects.range_offset_sigma = 0.0;
  const LidarInertialSim other_ideal(other);
  const io::PointCloud p = other_ideal.Scan(5), q = same_unit.Scan(5);
  ASSERT_EQ(p.size(), q.size());
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(q.points[i].norm() - p.points[i].norm(), offset[q.ring[i]], 1e-9);
  }
  // Another unit: other offsets.
  c.lidar.unit_seed = 8;
  const io::PointCloud r = LidarInertialSim(c).Scan(3);
  ASSERT_EQ(r.size(), a.size());
  EXPECT_GT(std::abs((r.points[0].norm() - a.points[0].norm()) - offset[r.ring[0]]), 1e-6);
}

TEST(SensorEffects, BeamAngleErrorsBelongToTheUnitNotTheSequence) {
  SimConfig c = Quiet();
  c.lidar.effects.elevation_error_deg = 0.2;
  c.lidar.effects.azimuth_error_deg = 0.2;
  SimConfig d = c;
  d.seed = c.seed + 1;  // another noise seed: IMU noise differs, the lidar has no noise
  // Without a unit seed the errors follow the noise seed (as before the unit effects)...
  EXPECT_FALSE(SameScan(LidarInertialSim(c).Scan(2), LidarInertialSim(d).Scan(2)));
  // ...with one they are the unit's, whatever the sequence's seed.
  c.lidar.unit_seed = d.lidar.unit_seed = 99;
  EXPECT_TRUE(SameScan(LidarInertialSim(c).Scan(2), LidarInertialSim(d).Scan(2)));
  d.lidar.unit_seed = 100;
  EXPECT_FALSE(SameScan(LidarInertialSim(c).Scan(2), LidarInertialSim(d).Scan(2)));
}

TEST(SensorEffects, FootprintSpreadGrowsWithRangeAndIncidence) {
  SimConfig c = Quiet();
  const LidarInertialSim ideal(c);
  c.lidar.effects.beam_divergence_rad = 3e-3;
  const LidarInertialSim spread(c);
  // With no other noise the range error is n·r·δ·tanθ/√12, n ~ N(0, 1): normalised, σ = 1.
  double sq = 0.0;
  int n = 0;
  for (size_t k : {2, 5, 9}) {
    const io::PointCloud a = ideal.Scan(k), b = spread.Scan(k);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      const auto [r, cos_i] = TrueHit(ideal, a.times_ns[i], a.points[i]);
      const double tan_i = std::min(std::sqrt(1.0 - cos_i * cos_i) / cos_i, 20.0);
      const double sigma = r * 3e-3 * tan_i / std::sqrt(12.0);
      if (sigma < 1e-4) continue;
      const double e = (b.points[i].norm() - a.points[i].norm()) / sigma;
      sq += e * e;
      ++n;
    }
  }
  ASSERT_GT(n, 3000);
  EXPECT_NEAR(std::sqrt(sq / n), 1.0, 0.05);
  // Deterministic: the same scan twice.
  EXPECT_TRUE(SameScan(spread.Scan(2), LidarInertialSim(c).Scan(2)));
}

TEST(SensorEffects, MixedPixelsLieBetweenTheTwoSurfacesOfAnEdge) {
  // The street: façades, cars and poles make depth edges.
  SimConfig c = Quiet(WorldKind::kStreet, Regime::kVehicle);
  c.lidar.firing_decimation = 4;
  const LidarInertialSim ideal(c);
  c.lidar.effects.mixed_pixel_probability = 1.0;
  c.lidar.effects.mixed_pixel_min_gap = 0.3;
  const LidarInertialSim mixed(c);
  const io::PointCloud a = ideal.Scan(6), b = mixed.Scan(6);
  const auto rays = ByRay(a);
  std::map<int64_t, int> firing;  // time → firing index
  for (int f = 0; f < c.lidar.firings_per_revolution; f += 4) firing[ideal.FiringTimeNs(6, f)] = f;
  int moved = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    const auto it = rays.find({b.times_ns[i], b.ring[i]});
    if (it == rays.end()) continue;  // its true range was out of bounds
    const double r = it->second.norm(), m = b.points[i].norm();
    if (std::abs(m - r) < 1e-9) continue;
    ++moved;
    // Between r and the true range of the previous firing of the beam.
    const int f = firing.at(b.times_ns[i]);
    ASSERT_GT(f, 0);
    const auto n = rays.find({ideal.FiringTimeNs(6, f - 4), b.ring[i]});
    const bool between = n != rays.end() && std::abs(n->second.norm() - r) > 0.3 &&
                         m >= std::min(r, n->second.norm()) - 1e-9 &&
                         m <= std::max(r, n->second.norm()) + 1e-9;
    EXPECT_TRUE(between) << "ring " << b.ring[i] << " range " << r << " -> " << m;
  }
  EXPECT_GT(moved, 20);
  EXPECT_LT(moved, int(b.size()) / 4);  // edges, not surfaces
  c.lidar.effects.mixed_pixel_probability = 0.0;
  EXPECT_TRUE(SameScan(LidarInertialSim(c).Scan(6), a));
}

TEST(SensorEffects, GrazingDropoutsFollowTheirRamp) {
  SimConfig c = Quiet();
  c.lidar.firing_decimation = 2;
  const LidarInertialSim ideal(c);
  c.lidar.effects.grazing_dropout_start_deg = 60.0;
  const LidarInertialSim grazing(c);
  double expected_lost = 0.0;
  size_t lost = 0, kept_steep = 0, all_steep = 0;
  for (size_t k : {3, 7}) {
    const io::PointCloud a = ideal.Scan(k), b = grazing.Scan(k);
    const auto kept = ByRay(b);
    for (size_t i = 0; i < a.size(); ++i) {
      const double theta = std::acos(TrueHit(ideal, a.times_ns[i], a.points[i]).second);
      const bool here = kept.count({a.times_ns[i], a.ring[i]}) > 0;
      if (theta <= M_PI / 3) {
        ++all_steep;
        kept_steep += here;
      } else {
        expected_lost += (theta - M_PI / 3) / (M_PI / 6);
        lost += !here;
      }
    }
  }
  EXPECT_EQ(kept_steep, all_steep);  // below the start nothing is lost
  ASSERT_GT(expected_lost, 200.0);
  EXPECT_NEAR(double(lost) / expected_lost, 1.0, 4.0 / std::sqrt(expected_lost));
}

TEST(SensorEffects, OnlyWhereAskedFor) {
  // Without a preset (Table II's simulator) nothing; the presets carry their sensor's family.
  const SimConfig none = PresetConfig(Preset::kNone, 2);
  EXPECT_EQ(none.lidar.unit_seed, 0u);
  EXPECT_EQ(none.lidar.effects.beam_divergence_rad, 0.0);
  EXPECT_EQ(none.lidar.effects.mixed_pixel_probability, 0.0);
  EXPECT_EQ(none.lidar.effects.elevation_error_deg, 0.0);
  const SimConfig nc = PresetConfig(Preset::kNewerCollege, 2);
  EXPECT_EQ(nc.lidar.effects.elevation_error_deg, SensorEffectsOf("ouster").elevation_error_deg);
  EXPECT_GT(nc.lidar.effects.beam_divergence_rad, 0.0);
  const SimConfig kitti = PresetConfig(Preset::kKitti, 2);
  EXPECT_EQ(kitti.lidar.effects.range_offset_sigma, SensorEffectsOf("hdl64").range_offset_sigma);
  // One unit per experiment seed: every index shares it, another seed is another unit.
  EXPECT_EQ(PresetConfig(Preset::kKitti, 5).lidar.unit_seed, kitti.lidar.unit_seed);
  EXPECT_NE(PresetConfig(Preset::kKitti, 2, 11).lidar.unit_seed, kitti.lidar.unit_seed);
  // Asked for off: the preset's lidar as it was; asked for without a preset: there.
  SimOverrides off;
  off.sensor_effects = "off";
  const SimConfig plain = PresetConfig(Preset::kNewerCollege, 2, kExperimentSeed, off);
  EXPECT_EQ(plain.lidar.unit_seed, 0u);
  EXPECT_EQ(plain.lidar.effects.beam_divergence_rad, 0.0);
  EXPECT_EQ(plain.lidar.effects.grazing_dropout_start_deg, 90.0);
  SimOverrides on;
  on.sensor_effects = "velodyne";
  EXPECT_GT(PresetConfig(Preset::kNone, 2, kExperimentSeed, on).lidar.effects.range_offset_sigma,
            0.0);
  on.sensor_effects = "lidar";
  EXPECT_THROW(PresetConfig(Preset::kNone, 2, kExperimentSeed, on), std::runtime_error);
  LidarConfig L;
  EXPECT_THROW(ApplySensorEffects(SensorEffectsOf("ouster"), 0, &L), std::runtime_error);
}

TEST(SensorEffects, InvalidValuesAreRejected) {
  auto bad = [](auto edit) {
    SimConfig c = Quiet();
    edit(c.lidar);
    EXPECT_THROW(LidarInertialSim{c}, std::runtime_error);
  };
  bad([](LidarConfig& L) { L.effects.range_offset_sigma = -0.01; });
  bad([](LidarConfig& L) { L.effects.beam_divergence_rad = -1e-3; });
  bad([](LidarConfig& L) { L.effects.mixed_pixel_probability = 1.5; });
  bad([](LidarConfig& L) { L.effects.mixed_pixel_min_gap = -1.0; });
  bad([](LidarConfig& L) { L.effects.grazing_dropout_start_deg = 95.0; });
  bad([](LidarConfig& L) { L.effects.grazing_dropout_start_deg = std::nan(""); });
}

}  // namespace
}  // namespace ctlio::sim
