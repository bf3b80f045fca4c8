// The lidar-inertial simulator (SPEC §6): motion draws, ground-truth integration, exact specific
// force vs the body-centric model, ray casting, per-point timestamps, noise levels, determinism
// and the scan/IMU partition of the in-memory data source.
#include "ctlio/sim/lidar_inertial_sim.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ctlio::sim {
namespace {

// A small configuration for tests: few beams and firings (full resolution is benchmarked).
SimConfig SmallConfig(Regime regime = Regime::kFast, int index = 0) {
  SimConfig c = ExperimentConfig(regime, index);
  c.duration_s = 2.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 20;
  return c;
}

// Distance from a world point to the nearest face of the room box.
double WallDistance(const RoomConfig& room, const Vec3& p) {
  double d = 1e9;
  for (int i = 0; i < 3; ++i) {
    d = std::min(d, std::abs(p[i] - room.min[i]));
    d = std::min(d, std::abs(p[i] - room.max[i]));
  }
  return d;
}

TEST(DrawMotion, RegimeRangesAndDeterminism) {
  for (int i = 0; i < 20; ++i) {
    const MotionProfile s = DrawMotion(Regime::kSlow, i), m = DrawMotion(Regime::kMedium, i),
                        f = DrawMotion(Regime::kFast, i);
    for (int j = 0; j < 3; ++j) {
      EXPECT_GE(s.axes[j].amplitude, 0.1);
      EXPECT_LT(s.axes[j].amplitude, 0.5);
      EXPECT_GE(s.axes[j].frequency, 0.5);
      EXPECT_LT(s.axes[j].frequency, 1.0);
      EXPECT_EQ(s.axes[3 + j].amplitude, 0.0);  // slow: no rotation
      EXPECT_GE(m.axes[j].amplitude, 0.5);
      EXPECT_LT(m.axes[j].amplitude, 1.0);
      EXPECT_GE(m.axes[3 + j].frequency, 2.0);
      EXPECT_LT(m.axes[3 + j].frequency, 4.0);
      EXPECT_GE(f.axes[j].frequency, 2.0);
      EXPECT_LT(f.axes[j].frequency, 4.0);
      EXPECT_GE(f.axes[3 + j].amplitude, 1.0);
      EXPECT_LT(f.axes[3 + j].amplitude, 2.0);
      EXPECT_GE(f.axes[3 + j].frequency, 4.0);
      EXPECT_LT(f.axes[3 + j].frequency, 8.0);
    }
    EXPECT_EQ(f.axes[5].amplitude, DrawMotion(Regime::kFast, i).axes[5].amplitude);
    EXPECT_NE(f.axes[0].amplitude, DrawMotion(Regime::kFast, i + 1).axes[0].amplitude);
    EXPECT_DOUBLE_EQ(f.start_s, 0.2);
  }
  EXPECT_EQ(ParseRegime("medium"), Regime::kMedium);
  EXPECT_THROW(ParseRegime("warp"), std::runtime_error);
}

TEST(LidarInertialSim, PoseIntegrationMatchesTwistAndFinerGrid) {
  SimConfig c = SmallConfig();
  const LidarInertialSim sim(c);
  c.integration_step_s = 1e-5;
  const LidarInertialSim fine(c);
  for (double t : {0.1, 0.5, 1.234567, 1.99}) {
    // 4th-order Magnus on a 0.1 ms grid agrees with a 10 µs grid to ~1e-9.
    const Vec6 d = (sim.WorldFromImu(t).Inverse() * fine.WorldFromImu(t)).Log();
    EXPECT_LT(d.norm(), 1e-8) << t;
    // The pose derivative is the body twist: Log(T(t−δ)⁻¹T(t+δ))/2δ = ξ(t) + O(δ²).
    const double dt = 1e-5;
    const Vec6 xi =
        (sim.WorldFromImu(t - dt).Inverse() * sim.WorldFromImu(t + dt)).Log() / (2 * dt);
    EXPECT_LT((xi - sim.BodyTwist(t)).norm(), 1e-5) << t;
  }
  // Stationary for the first 0.2 s.
  EXPECT_LT((sim.WorldFromImu(0.19).Log() - c.world_from_imu0.Log()).norm(), 1e-15);
  EXPECT_EQ(sim.BodyTwist(0.15).norm(), 0.0);
  EXPECT_GT(sim.BodyTwist(0.25).norm(), 0.1);
}

TEST(LidarInertialSim, ExactSpecificForceAndBodyCentricModel) {
  SimConfig c = SmallConfig();
  const LidarInertialSim sim(c);
  const Vec3 g_w(0, 0, -c.imu.gravity);
  for (double t : {0.4, 0.77, 1.5}) {
    // World acceleration by central differences of the integrated position.
    const double h = 1e-4;
    const Vec3 a_w =
        (sim.WorldFromImu(t + h).translation() - 2 * sim.WorldFromImu(t).translation() +
         sim.WorldFromImu(t - h).translation()) /
        (h * h);
    const Mat3 C = sim.WorldFromImu(t).rotation();
    const io::ImuSample s = sim.TrueImu(t);
    EXPECT_LT((s.accel - C.transpose() * (a_w - g_w)).norm(), 2e-3) << t;
    EXPECT_LT((s.gyro - sim.BodyTwist(t).tail<3>()).norm(), 1e-15);
    // The paper's body-centric model lacks exactly ω×v (SPEC §3).
    SimConfig cb = c;
    cb.imu.body_centric = true;
    const LidarInertialSim body(cb);
    const Vec6 xi = sim.BodyTwist(t);
    const Vec3 wxv = xi.tail<3>().cross(xi.head<3>());
    EXPECT_GT(wxv.norm(), 1e-3);
    EXPECT_LT((s.accel - body.TrueImu(t).accel - wxv).norm(), 1e-12);
  }
  // At rest the accelerometer reads −C_wbᵀ g = [0, 0, g] (level start), plus bias.
  EXPECT_LT((sim.TrueImu(0.1).accel - Vec3(0, 0, c.imu.gravity)).norm(), 1e-12);
}

// An IMU at T_bi (rotated, on a lever arm p) reads the motion of its own origin: the specific
// force from the second difference of p_w(t) = T_wb(t)·p, in the IMU frame. The simulator's
// ω̇×p + ω×(ω×p) are not written here; their size (> 0.1 m/s² in the fast regime) gives the
// comparison teeth.
TEST(LidarInertialSim, ImuOnALeverArmReadsTheMotionOfItsOwnOrigin) {
  SimConfig c = SmallConfig();
  const LidarInertialSim sim(c);
  const SE3 T_bi(so3::Exp(Vec3(0.3, -1.2, 2.0)), Vec3(0.3, -0.2, 0.1));
  const Vec3 g_w(0, 0, -c.imu.gravity);
  const Mat3 C_ib = T_bi.rotation().transpose();
  for (double t : {0.4, 0.77, 1.5}) {
    const double h = 1e-4;
    const auto origin = [&](double x) { return (sim.WorldFromImu(x) * T_bi).translation(); };
    const Vec3 a_w = (origin(t + h) - 2 * origin(t) + origin(t - h)) / (h * h);
    const Mat3 C_wi = sim.WorldFromImu(t).rotation() * T_bi.rotation();
    const io::ImuSample s = sim.TrueImu(t, T_bi);
    EXPECT_LT((s.accel - C_wi.transpose() * (a_w - g_w)).norm(), 2e-3) << t;
    EXPECT_LT((s.gyro - C_ib * sim.BodyTwist(t).tail<3>()).norm(), 1e-14);
    EXPECT_GT((s.accel - C_ib * sim.TrueImu(t).accel).norm(), 0.1) << t;
  }
}

// Further IMUs leave IMU 0 bit-identical (their own noise streams), sample on their own clock
// grid (rate, start offset), carry their own biases, and are interleaved in time in AllImu().
TEST(LidarInertialSim, ExtraImusKeepTheFirstAndRunOnTheirOwnClock) {
  SimConfig c = SmallConfig();
  const LidarInertialSim one(c);
  ImuConfig second = c.imu;
  second.rate_hz = 400.0;
  second.clock_offset_s = 0.0013;
  second.body_from_imu = SE3(Mat3::Identity(), Vec3(0.3, 0, 0));
  second.accel_bias = Vec3::Constant(-0.1);
  second.outages = {{1.0, 0.5}};
  c.extra_imus = {second};
  const LidarInertialSim two(c);
  ASSERT_EQ(two.NumImus(), 2u);
  ASSERT_EQ(one.Imu().size(), two.Imu(0).size());
  for (size_t j = 0; j < one.Imu().size(); ++j) {
    EXPECT_EQ(one.Imu()[j].t_ns, two.Imu(0)[j].t_ns);
    EXPECT_EQ(one.Imu()[j].accel, two.Imu(0)[j].accel);
    EXPECT_EQ(one.Imu()[j].gyro, two.Imu(0)[j].gyro);
  }
  const auto& imu1 = two.Imu(1);
  EXPECT_EQ(imu1.front().t_ns - c.start_ns, 1300000);
  EXPECT_EQ(imu1[1].t_ns - imu1[0].t_ns, 2500000);
  for (const io::ImuSample& s : imu1) {
    EXPECT_EQ(s.imu, 1);
    const double t = two.Seconds(s.t_ns);
    EXPECT_FALSE(t >= 1.0 && t < 1.5) << t;  // IMU 1's outage, not IMU 0's
  }
  EXPECT_EQ(two.ImuBiases(1).front().head<3>(), Vec3::Constant(-0.1));
  EXPECT_EQ(two.ImuOutages(1).size(), 1u);
  EXPECT_TRUE(two.ImuOutages(0).empty());
  EXPECT_EQ(two.AllImu().size(), two.Imu(0).size() + imu1.size());
  for (size_t j = 1; j < two.AllImu().size(); ++j) {
    EXPECT_LE(two.AllImu()[j - 1].t_ns, two.AllImu()[j].t_ns);
  }
}

TEST(LidarInertialSim, ImuNoiseAndBiasLevels) {
  SimConfig c = SmallConfig();
  c.duration_s = 20.0;
  const LidarInertialSim sim(c);
  const auto& imu = sim.Imu();
  ASSERT_EQ(imu.size(), 4001u);  // 200 Hz, both ends
  EXPECT_EQ(imu[1].t_ns - imu[0].t_ns, 5'000'000);
  Vec6 mean = Vec6::Zero(), sq = Vec6::Zero();
  for (const auto& s : imu) {
    const io::ImuSample truth = sim.TrueImu(sim.Seconds(s.t_ns));
    Vec6 e;
    e << s.accel - truth.accel, s.gyro - truth.gyro;
    mean += e;
    sq += e.cwiseProduct(e);
  }
  mean /= double(imu.size());
  const Vec6 var = sq / double(imu.size()) - mean.cwiseProduct(mean);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(mean[k], 0.05, 0.0015);  // bias; σ/√4001 ≈ 3e-4 (accel)
    const double sigma = k < 3 ? c.imu.accel_noise : c.imu.gyro_noise;
    EXPECT_NEAR(std::sqrt(var[k]), sigma, 0.06 * sigma);
  }
}

TEST(LidarInertialSim, RayCasting) {
  SimConfig c = SmallConfig();
  c.room.obstacles.push_back({Vec3(10, -1, 0), Vec3(11, 1, 10)});
  const LidarInertialSim sim(c);
  const Vec3 o(0, 0, 2);
  EXPECT_DOUBLE_EQ(sim.CastRay(o, Vec3(0, 1, 0)), 50.0);
  EXPECT_DOUBLE_EQ(sim.CastRay(o, Vec3(0, 0, -1)), 2.0);
  EXPECT_DOUBLE_EQ(sim.CastRay(o, Vec3(0, 0, 1)), 8.0);
  EXPECT_DOUBLE_EQ(sim.CastRay(o, Vec3(1, 0, 0)), 10.0);  // the pillar
  EXPECT_DOUBLE_EQ(sim.CastRay(o, Vec3(-1, 0, 0)), 50.0);
  EXPECT_NEAR(sim.CastRay(o, Vec3(1, 1, 0).normalized()), 50.0 * std::sqrt(2.0), 1e-9);
}

TEST(LidarInertialSim, NoiseFreeScanPointsLieOnTheWallsAtTheirOwnTimes) {
  SimConfig c = SmallConfig();
  c.lidar.range_noise = 0.0;
  c.imu_from_lidar = SE3(so3::Exp(Vec3(0.1, -0.2, 3.0)), Vec3(0.1, 0.2, -0.05));
  const LidarInertialSim sim(c);
  for (size_t k : {0, 7, 19}) {  // stationary and moving (fast regime)
    const io::PointCloud cloud = sim.Scan(k);
    ASSERT_EQ(cloud.size(), 16u * 90u);  // all rays hit a wall
    ASSERT_EQ(cloud.times_ns.size(), cloud.size());
    EXPECT_EQ(cloud.stamp_ns, int64_t(k) * 100'000'000);
    EXPECT_GE(cloud.times_ns.front(), cloud.stamp_ns);
    EXPECT_LT(cloud.times_ns.back(), cloud.stamp_ns + 100'000'000);
    double worst = 0.0, worst_wrong_time = 0.0;
    for (size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 p = sim.WorldFromLidar(sim.Seconds(cloud.times_ns[i])) * cloud.points[i];
      worst = std::max(worst, WallDistance(c.room, p));
      const Vec3 q = sim.WorldFromLidar(sim.Seconds(cloud.stamp_ns)) * cloud.points[i];
      worst_wrong_time = std::max(worst_wrong_time, WallDistance(c.room, q));
    }
    EXPECT_LT(worst, 1e-9) << k;
    // Ignoring the per-point times (no deskew) misplaces points in a moving scan.
    if (k > 2) EXPECT_GT(worst_wrong_time, 0.05) << k;
  }
}

TEST(LidarInertialSim, RangeNoiseLevelFullResolutionCountAndDeterminism) {
  SimConfig c = ExperimentConfig(Regime::kMedium, 4);
  c.duration_s = 0.3;
  const LidarInertialSim sim(c);
  const io::PointCloud cloud = sim.Scan(1);
  EXPECT_EQ(cloud.size(), 128u * 1800u);  // full resolution: 230,400 points
  double sq = 0.0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const SE3 T = sim.WorldFromLidar(sim.Seconds(cloud.times_ns[i]));
    const Vec3 d = cloud.points[i].normalized();
    const double r = sim.CastRay(T.translation(), T.rotation() * d);
    sq += std::pow(cloud.points[i].norm() - r, 2);
  }
  EXPECT_NEAR(std::sqrt(sq / double(cloud.size())), 0.02, 0.0005);
  // Random access equals a fresh simulator's scan: a scan is a function of (seed, index).
  const LidarInertialSim again(c);
  const io::PointCloud same = again.Scan(1);
  ASSERT_EQ(same.size(), cloud.size());
  EXPECT_EQ(same.points[12345], cloud.points[12345]);
  EXPECT_EQ(same.times_ns.back(), cloud.times_ns.back());
  SimConfig other = c;
  other.seed += 1;
  EXPECT_NE(LidarInertialSim(other).Scan(1).points[12345], cloud.points[12345]);
}

// FNV-1a over the IMU stream and three scans (every byte of every value).
uint64_t OutputHash(const SimConfig& c) {
  const LidarInertialSim sim(c);
  uint64_t h = 1469598103934665603ULL;
  auto add = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  for (const auto& m : sim.Imu()) {
    add(&m.t_ns, 8);
    add(m.accel.data(), 24);
    add(m.gyro.data(), 24);
  }
  for (size_t k : {0, 5, 13}) {
    const io::PointCloud cl = sim.Scan(k);
    for (size_t i = 0; i < cl.size(); ++i) {
      add(cl.points[i].data(), 24);
      add(&cl.times_ns[i], 8);
      add(&cl.ring[i], 2);
    }
  }
  return h;
}

// The box world with default options is the simulator as it was before the other worlds and
// the realism options existed: the two hashes were printed by the simulator of commit bdb63a7
// (the same configurations, built alone from that commit's apps/sim).
TEST(LidarInertialSim, BoxWorldReproducesThePreviousSimulatorBitForBit) {
  SimConfig a = ExperimentConfig(Regime::kMedium, 3);
  a.duration_s = 2.0;
  a.lidar.beams = 16;
  a.lidar.firing_decimation = 10;
  SimConfig b = ExperimentConfig(Regime::kFast, 7, kExperimentSeed, WorldKind::kBox);
  b.duration_s = 2.0;
  b.lidar.beams = 32;
  b.lidar.firing_decimation = 7;
  b.room.obstacles.push_back({Vec3(3, -1, 0), Vec3(4, 1, 10)});
  b.imu_from_lidar = SE3(so3::Exp(Vec3(0.1, -0.2, 3.0)), Vec3(0.1, 0.2, -0.05));
  b.imu.accel_bias_walk = 0.01;
  b.imu.gyro_bias_walk = 0.001;
  b.imu.body_centric = true;
  EXPECT_EQ(OutputHash(a), 0xe60e40d713b7d8c1ULL);
  EXPECT_EQ(OutputHash(b), 0xcc2dc4f2bf94d806ULL);
}

TEST(SimulatedSource, PartitionsImuBetweenScansAndHasGroundTruth) {
  SimConfig c = SmallConfig(Regime::kMedium, 2);
  c.imu_from_lidar = SE3(so3::Exp(Vec3(0, 0, M_PI)), Vec3(0.1, 0, 0));
  SimulatedSource source(c);
  EXPECT_EQ(source.NumScans(), 20u);
  io::ScanFrame f;
  int64_t prev_end = -1;
  size_t imu = 0, scans = 0;
  while (source.Next(&f)) {
    EXPECT_EQ(f.index, scans);
    EXPECT_EQ(f.start_ns, f.cloud.stamp_ns);
    EXPECT_EQ(f.end_ns, f.cloud.times_ns.back());
    for (const auto& s : f.imu) {
      EXPECT_GT(s.t_ns, prev_end);
      EXPECT_LE(s.t_ns, f.end_ns);
    }
    imu += f.imu.size();
    prev_end = f.end_ns;
    ++scans;
  }
  EXPECT_EQ(scans, 20u);
  EXPECT_EQ(imu, 400u);  // samples up to the last firing at 1.9945 s: 0 … 1.990 s
  const auto gt = source.GroundTruth();
  ASSERT_TRUE(gt.has_value());
  EXPECT_EQ(gt->size(), 401u + 20u);  // IMU times + scan ends
  const LidarInertialSim& sim = source.simulator();
  for (const auto& p : *gt) {
    const SE3 expect = sim.WorldFromImu(sim.Seconds(p.t_ns)) * c.imu_from_lidar;
    EXPECT_LT((p.pose.Inverse() * expect).Log().norm(), 1e-12);
  }
  EXPECT_DOUBLE_EQ(*source.Gravity(), 9.81);
}

}  // namespace
}  // namespace ctlio::sim
