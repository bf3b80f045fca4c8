// Each simulated sensor written as its driver would (driver_conventions.h) into a ROS 1 bag and
// read back: topics, per-point time field detected as that driver's, times decoded back to the
// simulated times (1 ns; float32 relative seconds: its precision), rings, the Livox IMU in g, and
// the Livox CustomMsg as the lidar topic type.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>

#include <cmath>
#include <filesystem>

#include "common/temp_dir.h"
#include "common/test_paths.h"
#include "ctlio/io/bag_sensor_suggestion.h"
#include "ctlio/io/bag_writer.h"
#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/sim/presets.h"
#include "ctlio/sim/sensor_models.h"
#include "io/same_frames.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;

sim::SimConfig SensorSim(const std::string& sensor,
                         int64_t start_ns = 1'700'000'000'123'456'789LL) {
  sim::SimOverrides o;
  o.sensor = sensor;
  o.duration_s = 0.5;
  o.firing_decimation = 25;
  sim::SimConfig c = sim::PresetConfig(sim::Preset::kNone, 2, sim::kExperimentSeed, o);
  c.start_ns = start_ns;  // default: a 2023 epoch time, absolute fields at full size
  return c;
}

struct Case {
  std::string sensor;
  PointFormat format;
  std::string topic, type, driver;
  int64_t time_tolerance_ns;
};

std::string DatatypeOf(const std::string& bag_path, const std::string& topic) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View v(bag, rosbag::TopicQuery(topic));
  for (const rosbag::ConnectionInfo* c : v.getConnections()) return c->datatype;
  return "";
}

TEST(SensorBags, EachDriverRoundTrips) {
  const fs::path d = testing::FreshTempDir("sensor_bags");
  // The fields' own precision at a 2023 epoch time: Hesai's float64 absolute seconds at 1.7e9 s
  // have a 2^-22 s ≈ 238 ns step, Livox's float64 absolute ns at 1.7e18 ns a 256 ns step (half of
  // it is the rounding error); Velodyne's float32 relative seconds (|t| ≤ 0.1 s) ≈ 7 ns.
  const std::vector<Case> cases = {
      {"os1_128", PointFormat::kOuster, "/ouster/points", "sensor_msgs/PointCloud2", "Ouster", 0},
      {"vlp16", PointFormat::kVelodyne, "/velodyne_points", "sensor_msgs/PointCloud2", "Velodyne",
       8},
      {"pandar_xt32", PointFormat::kHesai, "/hesai/pandar", "sensor_msgs/PointCloud2",
       "Hesai/Robosense", 239},
      {"mid360", PointFormat::kLivoxCustomMsg, "/livox/lidar", "livox_ros_driver2/CustomMsg",
       "Livox CustomPoint", 0},
      {"avia", PointFormat::kLivoxPointCloud2, "/livox/lidar", "sensor_msgs/PointCloud2",
       "Livox driver 2", 128},
  };
  // Near time 0 (the simulator's bags start at 1 s) every field but Velodyne's float32 is exact.
  for (const int64_t start : {1'700'000'000'123'456'789LL, 1'000'000'000LL})
    for (const Case& k : cases) {
      SCOPED_TRACE(k.sensor + " from " + std::to_string(start));
      const int64_t tolerance =
          start == 1'000'000'000LL && k.format != PointFormat::kVelodyne ? 0 : k.time_tolerance_ns;
      const std::string bag = (d / (k.sensor + std::to_string(start) + ".bag")).string();
      sim::SimulatedSource written(SensorSim(k.sensor, start));
      RosbagWriteOptions wo;
      DriverConvention driver = sim::FindSensorModel(k.sensor).driver;
      driver.format = k.format;
      wo.UseDriver(driver);
      ASSERT_EQ(WriteRosbag(written, bag, wo), 5u);
      EXPECT_EQ(DatatypeOf(bag, k.topic), k.type);
      RosbagOptions ro;
      ro.accel_scale = driver.accel_unit;
      RosbagSource read(bag, ro);
      EXPECT_EQ(read.lidar_topic(), k.topic);
      EXPECT_EQ(read.imu_topic(), driver.imu_topic);
      const sim::LidarInertialSim truth(SensorSim(k.sensor, start));
      ScanFrame f;
      size_t scans = 0;
      while (read.Next(&f)) {
        const PointCloud expected = truth.Scan(f.index);
        ASSERT_EQ(f.cloud.size(), expected.size());
        ASSERT_GT(f.cloud.size(), 100u);
        EXPECT_LE(std::abs(f.start_ns - expected.times_ns.front()), tolerance);
        int64_t worst = 0;
        for (size_t i = 0; i < expected.size(); ++i) {
          worst = std::max(worst, std::abs(f.cloud.times_ns[i] - expected.times_ns[i]));
          ASSERT_LT((f.cloud.points[i] - expected.points[i]).norm(), 2e-5);  // float32
        }
        EXPECT_LE(worst, tolerance) << "scan " << f.index;
        if (k.format == PointFormat::kVelodyne || k.format == PointFormat::kHesai) {
          EXPECT_EQ(f.cloud.ring, expected.ring);
        }
        for (const ImuSample& s : f.imu) {
          const auto& all = truth.Imu();
          const auto it = std::find_if(all.begin(), all.end(),
                                       [&](const ImuSample& t) { return t.t_ns == s.t_ns; });
          ASSERT_NE(it, all.end());
          EXPECT_LT((s.accel - it->accel).norm(), 1e-12);  // Livox: g in the bag, scaled back
        }
        ++scans;
      }
      EXPECT_EQ(scans, 5u);
    }
}

// Issue 41: every driver's layout, the Livox CustomMsg included, reads the same from a ROS 2 bag
// (MCAP with zstd, SQLite) as from the ROS 1 bag: the same frames to the bit, through one reader.
TEST(SensorBags, EachDriverReadsTheSameFromRos1AndRos2Bags) {
  const fs::path d = testing::FreshTempDir("sensor_bags_ros2");
  for (const std::string sensor : {"mid360", "avia", "vlp16", "pandar_xt32"}) {
    SCOPED_TRACE(sensor);
    const DriverConvention driver = sim::FindSensorModel(sensor).driver;
    RosbagWriteOptions wo;
    wo.UseDriver(driver);
    const std::string ros1 = (d / (sensor + ".bag")).string();
    {
      sim::SimulatedSource written(SensorSim(sensor));
      ASSERT_EQ(WriteRosbag(written, ros1, wo), 5u);
    }
    for (const ros2::Ros2Storage storage :
         {ros2::Ros2Storage::kMcap, ros2::Ros2Storage::kSqlite3}) {
      const std::string ros2_bag =
          (d / (sensor + (storage == ros2::Ros2Storage::kMcap ? "_mcap" : "_db3"))).string();
      {
        sim::SimulatedSource written(SensorSim(sensor));
        Ros2WriteOptions r;
        r.storage = storage;
        r.compression = storage == ros2::Ros2Storage::kMcap ? ros2::Ros2Compression::kZstd
                                                            : ros2::Ros2Compression::kNone;
        ASSERT_EQ(WriteRos2Bag(written, ros2_bag, wo, r), 5u);
      }
      RosbagOptions ro;
      ro.accel_scale = driver.accel_unit;
      BagSource a(ros1, ro), b(ros2_bag, ro);
      EXPECT_EQ(a.lidar_topic(), b.lidar_topic());
      EXPECT_EQ(b.Name().rfind("ros2bag:", 0), 0u);
      EXPECT_EQ(testing::ExpectSameFrames(a, b), 5u);
    }
  }
}

// A Livox bag carries its IMU in g: read without the scale, the specific force is ≈ 1.
TEST(SensorBags, LivoxImuIsInG) {
  const fs::path d = testing::FreshTempDir("sensor_bags_g");
  const std::string bag = (d / "mid360.bag").string();
  sim::SimulatedSource written(SensorSim("mid360"));
  RosbagWriteOptions wo;
  wo.UseDriver(sim::FindSensorModel("mid360").driver);
  EXPECT_FALSE(wo.write_tf_static);  // lidar and IMU share livox_frame, as the driver's
  WriteRosbag(written, bag, wo);
  RosbagSource read(bag);
  ScanFrame f;
  ASSERT_TRUE(read.Next(&f));
  ASSERT_FALSE(f.imu.empty());
  EXPECT_NEAR(f.imu.front().accel.norm(), 9.81 / 9.80665, 0.02);
}

// A CustomMsg whose point_num disagrees with its points (a corrupt message) is an error naming the
// bag, topic and message, not a crash or a silent cloud.
TEST(SensorBags, CorruptCustomMsgInABagIsAnError) {
  const fs::path d = testing::FreshTempDir("sensor_bags_corrupt");
  const std::string path = (d / "bad.bag").string();
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    PointCloud c;
    c.stamp_ns = 1'000'000'000;
    c.points = {Vec3(1, 2, 3), Vec3(4, 5, 6)};
    c.times_ns = {c.stamp_ns, c.stamp_ns + 10};
    livox::CustomMsg m = livox::FromPointCloud(c, "livox_frame");
    m.point_num = 3;
    ros::Time t;
    t.fromNSec(1'100'000'000);
    bag.write("/livox/lidar", t, m);
    sensor_msgs::Imu imu;
    imu.header.stamp = t;
    bag.write("/livox/imu", t, imu);
  }
  try {
    RosbagSource read(path);
    ScanFrame f;
    read.Next(&f);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("/livox/lidar, message 1"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("point_num 3 but 2 points"));
  }
}

// Every sensor's bag, as its driver writes it, suggests that sensor's shipped config; the config
// file exists.
TEST(SensorBags, EachRecordingSuggestsItsOwnConfig) {
  const fs::path d = testing::FreshTempDir("sensor_bags_suggest");
  for (const sim::SensorModel& m : sim::SensorModels()) {
    SCOPED_TRACE(m.name);
    sim::SimConfig c = SensorSim(m.name, 1'000'000'000LL);
    c.duration_s = 0.2;
    RosbagWriteOptions wo;
    wo.UseDriver(m.driver);
    // The same recording as a ROS 1 bag and as a ROS 2 bag folder (MCAP).
    const std::string ros1 = (d / (m.name + ".bag")).string(), ros2 = (d / m.name).string();
    {
      sim::SimulatedSource written(c);
      WriteRosbag(written, ros1, wo);
    }
    {
      sim::SimulatedSource written(c);
      WriteRos2Bag(written, ros2, wo);
    }
    for (const std::string& bag : {ros1, ros2}) {
      const auto s = SuggestSensorConfigForBag(bag, m.driver.lidar_topic);
      ASSERT_TRUE(s.has_value()) << bag;
      EXPECT_EQ(s->sensor, m.name) << s->evidence;
      EXPECT_EQ(s->config, "data/sensors/" + m.name + ".yaml");
      EXPECT_TRUE(fs::is_regular_file(fs::path(ctlio::testing::SourceDir()) / s->config));
      EXPECT_EQ(s->note.empty(), m.driver.accel_unit == 1.0);  // Livox: the g advice
    }
  }
  EXPECT_FALSE(SuggestSensorConfigForBag((d / "absent.bag").string(), "/x").has_value());
}

TEST(SensorSuggestion, RulesOnTraits) {
  RecordingTraits t;
  t.lidar_topic = "/points_raw";
  t.lidar_type = "sensor_msgs/PointCloud2";
  EXPECT_FALSE(SuggestSensorConfig(t).has_value());  // nothing gives the driver away
  t.time_driver = "Velodyne";
  t.rings = 16;
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "vlp16");
  t.rings = 32;
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "hdl32e");
  t.time_driver = "Ouster";
  t.rings = 128;
  t.elevation_span_deg = 89;
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "os0_128");
  t.elevation_span_deg = 44;
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "os1_128");
  t.rings = 64;
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "os1_64");
  t.time_driver = "";
  t.lidar_topic = "/hesai/pandar";
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "pandar_xt32");
  PointCloud cloud;  // a forward wedge of ±30°: an Avia
  for (int a = -30; a <= 30; ++a) {
    cloud.points.push_back(Vec3(std::cos(a * M_PI / 180), std::sin(a * M_PI / 180), 0.1));
  }
  MeasureScan(cloud, &t);
  EXPECT_NEAR(t.azimuth_span_deg, 60.0, 1e-9);
  t.lidar_topic = "/livox/lidar";
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "avia");
  cloud.points.push_back(Vec3(-1, 0, 0));
  cloud.points.push_back(Vec3(0, -1, 0));
  MeasureScan(cloud, &t);
  EXPECT_NEAR(t.azimuth_span_deg, 210.0, 1e-9);  // widest empty sector: 30° to 180°
  EXPECT_EQ(SuggestSensorConfig(t)->sensor, "mid360");
}

}  // namespace
}  // namespace ctlio::io
