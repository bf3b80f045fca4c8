// Sensor realism options of the simulator: IMU outages remove exactly the requested samples,
// scale factors and saturation are applied as documented, lidar returns are lost / noisier as
// documented, and every option leaves the rest of the output unchanged.
#include <gtest/gtest.h>

#include <cmath>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {
namespace {

SimConfig Small(Regime regime = Regime::kFast, int index = 0) {
  SimConfig c = ExperimentConfig(regime, index);
  c.duration_s = 4.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 20;
  return c;
}

bool SameSample(const io::ImuSample& a, const io::ImuSample& b) {
  return a.t_ns == b.t_ns && a.accel == b.accel && a.gyro == b.gyro;
}

TEST(ImuOutages, ParseTheIntervalList) {
  const auto o = ParseImuOutages("5.0:0.5,12:2");
  ASSERT_EQ(o.size(), 2u);
  EXPECT_DOUBLE_EQ(o[0].start_s, 5.0);
  EXPECT_DOUBLE_EQ(o[0].length_s, 0.5);
  EXPECT_DOUBLE_EQ(o[1].start_s, 12.0);
  EXPECT_DOUBLE_EQ(o[1].length_s, 2.0);
  EXPECT_TRUE(ParseImuOutages("").empty());
  for (const char* bad : {"5", "5:", "a:1", "5:0", "5:-1", "5:1x", "-1:1"}) {
    EXPECT_THROW(ParseImuOutages(bad), std::runtime_error) << bad;
  }
}

TEST(ImuOutages, GivenIntervalsRemoveExactlyTheirSamples) {
  const SimConfig base = Small();
  SimConfig c = base;
  c.imu.outages = {{0.5, 0.25}, {2.0, 1.0}};  // [0.5, 0.75) and [2, 3)
  const LidarInertialSim full(base), gapped(c);
  size_t removed = 0, j = 0;
  for (const io::ImuSample& s : full.Imu()) {
    const double t = full.Seconds(s.t_ns);
    const bool inside =
        (t >= 0.5 - 1e-12 && t < 0.75 - 1e-12) || (t >= 2.0 - 1e-12 && t < 3.0 - 1e-12);
    if (inside) {
      ++removed;
      continue;
    }
    ASSERT_LT(j, gapped.Imu().size());
    EXPECT_TRUE(SameSample(s, gapped.Imu()[j])) << t;  // the others are untouched
    EXPECT_EQ(full.ImuBiases()[&s - full.Imu().data()], gapped.ImuBiases()[j]);
    ++j;
  }
  EXPECT_EQ(removed, 50u + 200u);  // 200 Hz: 0.25 s and 1 s
  EXPECT_EQ(j, gapped.Imu().size());
  EXPECT_EQ(gapped.ImuBiases().size(), gapped.Imu().size());
  // Lidar unaffected; the in-memory source hands out the stream with its holes.
  EXPECT_EQ(full.Scan(3).points, gapped.Scan(3).points);
  SimulatedSource source(c);
  io::ScanFrame f;
  size_t handed = 0;
  while (source.Next(&f)) handed += f.imu.size();
  EXPECT_EQ(handed, gapped.Imu().size() - 1);  // all but the sample after the last firing
}

TEST(ImuOutages, RandomOutagesFollowTheirRateAndLengths) {
  SimConfig c = Small();
  c.duration_s = 20.0;
  c.imu.outage_rate = 0.5;
  c.imu.outage_length_min = 0.2;
  c.imu.outage_length_max = 0.6;
  const LidarInertialSim sim(c);
  const auto& outages = sim.ImuOutages();
  EXPECT_GE(outages.size(), 3u);  // Poisson mean 10 over 20 s
  EXPECT_LE(outages.size(), 20u);
  for (const ImuOutage& o : outages) {
    EXPECT_GE(o.length_s, 0.2);
    EXPECT_LT(o.length_s, 0.6);
    EXPECT_LT(o.start_s, 20.0);
  }
  for (const io::ImuSample& s : sim.Imu()) {
    const double t = sim.Seconds(s.t_ns);
    for (const ImuOutage& o : outages) {
      EXPECT_FALSE(t >= o.start_s + 1e-9 && t < o.start_s + o.length_s - 1e-9) << t;
    }
  }
  EXPECT_LT(sim.Imu().size(), 4001u);
  // Same seed, same outages.
  EXPECT_EQ(LidarInertialSim(c).ImuOutages().size(), outages.size());
}

TEST(ImuRealism, ScaleFactorsAndSaturationAsDocumented) {
  SimConfig c = Small();
  c.imu.accel_noise = c.imu.gyro_noise = 0.0;
  c.imu.accel_scale = Vec3(0.01, -0.02, 0.03);
  c.imu.gyro_scale = Vec3(-0.05, 0.04, 0.002);
  const LidarInertialSim scaled(c);
  for (const io::ImuSample& s : scaled.Imu()) {
    const io::ImuSample truth = scaled.TrueImu(scaled.Seconds(s.t_ns));
    const Vec3 a = (Vec3::Ones() + c.imu.accel_scale).cwiseProduct(truth.accel) + c.imu.accel_bias;
    const Vec3 g = (Vec3::Ones() + c.imu.gyro_scale).cwiseProduct(truth.gyro) + c.imu.gyro_bias;
    EXPECT_LT((s.accel - a).norm(), 1e-12);
    EXPECT_LT((s.gyro - g).norm(), 1e-12);
  }
  // Saturation clamps each axis at ±limit, leaves readings inside the range unchanged.
  SimConfig sat = Small();
  sat.imu.gyro_limit = 1.0;
  sat.imu.accel_limit = 12.0;
  const LidarInertialSim free(Small()), clipped(sat);
  int clamped = 0;
  for (size_t j = 0; j < free.Imu().size(); ++j) {
    const io::ImuSample &u = free.Imu()[j], &s = clipped.Imu()[j];
    for (int k = 0; k < 3; ++k) {
      EXPECT_DOUBLE_EQ(s.gyro[k], std::clamp(u.gyro[k], -1.0, 1.0));
      EXPECT_DOUBLE_EQ(s.accel[k], std::clamp(u.accel[k], -12.0, 12.0));
      clamped += std::abs(u.gyro[k]) > 1.0;
    }
  }
  EXPECT_GT(clamped, 100);  // the fast regime reaches 2 rad/s
}

TEST(LidarRealism, DropoutLosesTheRequestedFractionAndKeepsTheRest) {
  SimConfig c = Small(Regime::kMedium, 1);
  c.lidar.firing_decimation = 2;
  const LidarInertialSim full(c);
  c.lidar.dropout = 0.3;
  const LidarInertialSim lossy(c);
  const io::PointCloud a = full.Scan(5), b = lossy.Scan(5);
  EXPECT_NEAR(double(b.size()) / double(a.size()), 0.7, 0.01);  // 14,400 rays
  // The kept returns are exactly returns of the full scan, in order (same noise stream).
  size_t i = 0;
  for (size_t j = 0; j < b.size(); ++j) {
    while (i < a.size() && a.points[i] != b.points[j]) ++i;
    ASSERT_LT(i, a.size()) << j;
  }
}

TEST(LidarRealism, RangeDependentNoiseIncidenceAndBeamErrors) {
  SimConfig c = Small(Regime::kMedium, 1);
  c.lidar.range_noise = 0.0;
  c.lidar.range_noise_per_m = 0.01;
  const LidarInertialSim sim(c);
  const io::PointCloud cloud = sim.Scan(4);
  double sq = 0.0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const SE3 T = sim.WorldFromLidar(sim.Seconds(cloud.times_ns[i]));
    const double r = sim.CastRay(T.translation(), T.rotation() * cloud.points[i].normalized());
    sq += std::pow((cloud.points[i].norm() - r) / r, 2);
  }
  EXPECT_NEAR(std::sqrt(sq / double(cloud.size())), 0.01, 0.0006);

  // Grazing returns are lost: every kept return hits its wall at ≤ 60° incidence.
  SimConfig g = Small(Regime::kMedium, 1);
  g.lidar.max_incidence_deg = 60.0;
  const LidarInertialSim grazing(g);
  const io::PointCloud kept = grazing.Scan(4);
  EXPECT_LT(kept.size(), sim.Scan(4).size());
  for (size_t i = 0; i < kept.size(); ++i) {
    const SE3 T = grazing.WorldFromLidar(grazing.Seconds(kept.times_ns[i]));
    const Vec3 d = T.rotation() * kept.points[i].normalized();
    const RayHit h = grazing.world().scene.Cast(T.translation(), d, 500.0);
    ASSERT_TRUE(h.Valid());
    EXPECT_GE(std::abs(h.normal.dot(d)), std::cos(M_PI / 3) - 1e-9);
  }

  // Beam-angle errors: points are reported along the nominal beams, ranges differ.
  SimConfig e = Small(Regime::kMedium, 1);
  e.lidar.range_noise = 0.0;
  const LidarInertialSim nominal(e);
  e.lidar.effects.elevation_error_deg = 0.2;
  e.lidar.effects.azimuth_error_deg = 0.2;
  const LidarInertialSim biased(e);
  const io::PointCloud p = nominal.Scan(2), q = biased.Scan(2);
  ASSERT_EQ(p.size(), q.size());
  int differ = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_LT((p.points[i].normalized() - q.points[i].normalized()).norm(), 1e-12);
    differ += std::abs(p.points[i].norm() - q.points[i].norm()) > 1e-3;
  }
  EXPECT_GT(differ, int(p.size()) / 2);
}

TEST(Realism, InvalidOptionsAreRejected) {
  auto bad = [](auto edit) {
    SimConfig c = Small();
    edit(c);
    EXPECT_THROW(LidarInertialSim{c}, std::runtime_error);
  };
  bad([](SimConfig& c) { c.lidar.dropout = 1.5; });
  bad([](SimConfig& c) { c.lidar.max_incidence_deg = 0.0; });
  bad([](SimConfig& c) { c.lidar.reflect_range = -1.0; });
  bad([](SimConfig& c) { c.imu.gyro_limit = -1.0; });
  bad([](SimConfig& c) {
    c.imu.outage_rate = 1.0;
    c.imu.outage_length_min = 2.0;
    c.imu.outage_length_max = 1.0;
  });
}

}  // namespace
}  // namespace ctlio::sim
