// The simulator's sensor models (sensor_models.h, scan_pattern.h): datasheet beam tables, the
// Livox patterns' field of view, point rate and non-repetition, the IMU and extrinsic each model
// applies, and the errors of a wrong name or a conflicting --beams.
#include "ctlio/sim/sensor_models.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "ctlio/sim/presets.h"

namespace ctlio::sim {
namespace {

constexpr double kRad = 180.0 / M_PI;

SimConfig SensorConfig(const std::string& name, double duration_s = 0.3) {
  SimOverrides o;
  o.sensor = name;
  o.duration_s = duration_s;
  SimConfig c = PresetConfig(Preset::kNone, 0, kExperimentSeed, o);
  // A small room: every ray of every model returns within its range.
  c.room.min = Vec3(-10, -10, 0);
  c.room.max = Vec3(10, 10, 8);
  c.world_from_imu0 = SE3(Mat3::Identity(), Vec3(0, 0, 1.5));
  return c;
}

double Elevation(const Vec3& p) { return std::asin(p.z() / p.norm()) * kRad; }
double Azimuth(const Vec3& p) { return std::atan2(p.y(), p.x()) * kRad; }

TEST(SensorModels, NamesInOrderAndUnknownNameListsThem) {
  std::vector<std::string> names;
  for (const SensorModel& m : SensorModels()) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"os0_128", "os1_64", "os1_128", "vlp16", "hdl32e",
                                             "pandar_xt32", "mid360", "avia"}));
  try {
    FindSensorModel("vlp32");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("vlp32"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("pandar_xt32"), std::string::npos);
  }
  const std::string list = ListSensorModels();
  EXPECT_EQ(std::count(list.begin(), list.end(), '\n'), 8);
  EXPECT_EQ(list.rfind("avia", 0) == std::string::npos, true);  // one line each, os0_128 first
  EXPECT_EQ(list.rfind("os0_128", 0), 0u);
}

TEST(SensorModels, DatasheetBeamTables) {
  const auto& vlp = FindSensorModel("vlp16").lidar.elevations_deg;
  ASSERT_EQ(vlp.size(), 16u);
  for (int b = 0; b < 16; ++b) EXPECT_EQ(vlp[b], -15.0 + 2.0 * b);
  const auto& hdl = FindSensorModel("hdl32e").lidar.elevations_deg;
  ASSERT_EQ(hdl.size(), 32u);
  EXPECT_DOUBLE_EQ(hdl.front(), -30.67);
  EXPECT_DOUBLE_EQ(hdl[1], -29.33);
  EXPECT_DOUBLE_EQ(hdl[22], -1.33);
  EXPECT_DOUBLE_EQ(hdl[23], 0.0);
  EXPECT_DOUBLE_EQ(hdl.back(), 10.67);
  for (size_t b = 1; b < hdl.size(); ++b)
    EXPECT_NEAR(hdl[b] - hdl[b - 1], 4.0 / 3.0, 0.0067);  // 1.33 or 1.34
  const auto& xt = FindSensorModel("pandar_xt32").lidar.elevations_deg;
  ASSERT_EQ(xt.size(), 32u);
  for (int b = 0; b < 32; ++b) EXPECT_EQ(xt[b], -16.0 + b);
  const LidarConfig& os0 = FindSensorModel("os0_128").lidar;
  EXPECT_EQ(os0.beams, 128);
  EXPECT_EQ(os0.min_elevation_deg, -45.0);
  EXPECT_EQ(os0.max_elevation_deg, 45.0);
  EXPECT_EQ(FindSensorModel("os1_64").lidar.max_elevation_deg, 16.6);
  EXPECT_EQ(FindSensorModel("os1_128").lidar.max_elevation_deg, 22.5);
}

// The simulated points lie on the table's cones: elevation of every point = its ring's entry.
TEST(SensorModels, SimulatedSpinningPointsFollowTheBeamTable) {
  for (const std::string name : {"vlp16", "hdl32e", "pandar_xt32", "os0_128"}) {
    SimConfig c = SensorConfig(name);
    c.lidar.firing_decimation = 50;
    const LidarInertialSim sim(c);
    const io::PointCloud scan = sim.Scan(1);
    ASSERT_GT(scan.size(), 100u) << name;
    const LidarConfig& L = c.lidar;
    for (size_t i = 0; i < scan.size(); ++i) {
      const int b = scan.ring[i];
      const double expected =
          L.elevations_deg.empty()
              ? L.min_elevation_deg +
                    (L.max_elevation_deg - L.min_elevation_deg) * b / (L.beams - 1)
              : L.elevations_deg[b];
      ASSERT_NEAR(Elevation(scan.points[i]), expected, 1e-9) << name << " point " << i;
    }
  }
}

TEST(SensorModels, EachModelAppliesItsImuAndExtrinsic) {
  EXPECT_EQ(SensorConfig("os1_128").imu.rate_hz, 100.0);
  EXPECT_EQ(SensorConfig("vlp16").imu.rate_hz, 200.0);
  EXPECT_EQ(SensorConfig("hdl32e").imu.rate_hz, 400.0);
  EXPECT_EQ(SensorConfig("pandar_xt32").imu.rate_hz, 200.0);
  const SimConfig mid = SensorConfig("mid360");
  EXPECT_EQ(mid.imu.rate_hz, 200.0);
  EXPECT_NEAR(mid.imu.gyro_noise, 0.014 * M_PI / 180 * std::sqrt(200.0), 1e-15);
  EXPECT_EQ(mid.imu_from_lidar.translation(), Vec3(-0.011, -0.02329, 0.04412));
  EXPECT_EQ(FindSensorModel("mid360").driver.accel_unit, 9.80665);
  EXPECT_EQ(FindSensorModel("os1_64").driver.accel_unit, 1.0);
  EXPECT_EQ(SensorConfig("avia").imu_from_lidar.translation(), Vec3(0.04165, 0.02326, -0.0284));
  // ouster_ros's T_imu_lidar: rotation diag(−1, −1, 1).
  EXPECT_EQ(SensorConfig("os0_128").imu_from_lidar.rotation().diagonal(), Vec3(-1, -1, 1));
}

TEST(SensorModels, BeamsFlagConflictsWithADatasheetTable) {
  SimOverrides o;
  o.sensor = "vlp16";
  o.beams = 32;
  EXPECT_THROW(PresetConfig(Preset::kNone, 0, kExperimentSeed, o), std::runtime_error);
  o.beams = 16;  // the sensor's own count is fine
  EXPECT_EQ(PresetConfig(Preset::kNone, 0, kExperimentSeed, o).lidar.beams, 16);
  o.sensor = "os1_128";  // uniform Ouster spacing: --beams thins it
  o.beams = 32;
  EXPECT_EQ(PresetConfig(Preset::kNone, 0, kExperimentSeed, o).lidar.beams, 32);
}

// Livox: points per second as the datasheets (all rays return in the small room), inside the
// field of view, and the pattern does not repeat: the 0.2° cells hit grow with integration time.
TEST(SensorModels, LivoxRateFieldOfViewAndNonRepetition) {
  struct Case {
    std::string name;
    double points_per_second;
  };
  for (const Case& k : {Case{"mid360", 200000}, Case{"avia", 240000}}) {
    const SimConfig c = SensorConfig(k.name, 1.0);
    const LidarInertialSim sim(c);
    ASSERT_EQ(sim.NumScans(), 10u);
    size_t points = 0;
    std::set<std::pair<int, int>> one_frame, five_frames;
    for (size_t s = 0; s < 10; ++s) {
      const io::PointCloud scan = sim.Scan(s);
      points += scan.size();
      for (size_t i = 0; i < scan.size(); ++i) {
        const Vec3& p = scan.points[i];
        const double el = Elevation(p), az = Azimuth(p);
        if (k.name == "mid360") {
          ASSERT_GE(el, -7.0 - 1e-9);
          ASSERT_LE(el, 52.0 + 1e-9);
        } else {
          ASSERT_LE(std::abs(az), 35.2 + 1e-9);
          ASSERT_LE(std::abs(el), 38.6 + 1e-9);
        }
        const std::pair<int, int> cell{int(std::floor(az * 5)), int(std::floor(el * 5))};
        if (s == 0) one_frame.insert(cell);
        if (s < 5) five_frames.insert(cell);
      }
      ASSERT_EQ(scan.times_ns.front(), sim.ScanStartNs(s));
    }
    EXPECT_NEAR(double(points), k.points_per_second, 0.01 * k.points_per_second) << k.name;
    EXPECT_GT(double(five_frames.size()), 2.5 * double(one_frame.size()))
        << k.name << ": " << one_frame.size() << " cells in one frame, " << five_frames.size()
        << " in five";
  }
  // Mid-360: all four azimuth quadrants in one frame.
  const LidarInertialSim mid(SensorConfig("mid360"));
  std::set<int> quadrants;
  for (const Vec3& p : mid.Scan(0).points) quadrants.insert(int(std::floor(Azimuth(p) / 90.0)));
  for (int q = -2; q < 2; ++q) EXPECT_EQ(quadrants.count(q), 1u) << q;
}

TEST(ScanPattern, DirectionsAreUnitAndDeterministic) {
  const ScanPattern& p = FindSensorModel("avia").lidar.pattern;
  const Vec3 d = PatternDirection(p, 2, 6, 0.123456);
  EXPECT_NEAR(d.norm(), 1.0, 1e-15);
  EXPECT_EQ(d, PatternDirection(p, 2, 6, 0.123456));
  EXPECT_GT((d - PatternDirection(p, 3, 6, 0.123456)).norm(), 1e-3);  // lines differ
  // t = 0, line 0: both prisms deflect along +x: azimuth = the full half field of view.
  EXPECT_NEAR(Azimuth(PatternDirection(p, 0, 6, 0.0)), 35.2, 1e-12);
}

}  // namespace
}  // namespace ctlio::sim
