// ROS 1 bags (rosbag_source.h): the simulator written as a bag (plain and LZ4-compressed) and read
// back (exact times, float32 points, IMU, extrinsic from /tf_static, ground truth), every driver's
// time field through a PointCloud2 message, topic selection, and the bad inputs: a truncated or
// corrupted bag, a file that is not a bag, missing or ambiguous topics, a PointCloud2 without
// x/y/z or with wrong field types. No small real PointCloud2 + Imu bag is available offline, so
// all bags here are written by the tests.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "io/time_variants.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using ::ctlio::testing::ExpectError;

sim::SimConfig SmallSim() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 1);
  c.duration_s = 0.6;
  c.lidar.beams = 8;
  c.lidar.firing_decimation = 30;
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  return c;
}

std::vector<ScanFrame> ReadAll(DataSource& s) {
  std::vector<ScanFrame> out;
  ScanFrame f;
  while (s.Next(&f)) out.push_back(f);
  return out;
}

TEST(Rosbag, SimulatorRoundTripThroughABag) {
  const fs::path d = testing::FreshTempDir("rosbag_roundtrip");
  for (const std::string compression : {"none", "lz4"}) {
    SCOPED_TRACE(compression);
    const std::string bag = (d / ("sim_" + compression + ".bag")).string();
    sim::SimulatedSource written(SmallSim());
    RosbagWriteOptions wo;
    wo.compression = compression;
    const size_t n = WriteRosbag(written, bag, wo);
    ASSERT_TRUE(IsRosbagFile(bag));
    RosbagSource read(bag);
    EXPECT_EQ(read.NumScans(), n);
    EXPECT_EQ(read.lidar_topic(), "/os_cloud_node/points");  // the only PointCloud2 topic
    // /tf_static connects os_imu and os_lidar and takes precedence over the 2021 preset, which the
    // topic names match.
    EXPECT_THAT(read.ExtrinsicOrigin(), HasSubstr("/tf_static"));
    EXPECT_LT((read.ImuFromLidar().Matrix() - NewerCollegeImuFromLidar().Matrix()).norm(), 1e-15);
    sim::SimulatedSource truth(SmallSim());
    const auto a = ReadAll(read), b = ReadAll(truth);
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].start_ns, b[k].start_ns);
      EXPECT_EQ(a[k].end_ns, b[k].end_ns);
      ASSERT_EQ(a[k].cloud.size(), b[k].cloud.size());
      EXPECT_EQ(a[k].cloud.times_ns, b[k].cloud.times_ns);
      for (size_t i = 0; i < a[k].cloud.size(); ++i) {
        EXPECT_LT((a[k].cloud.points[i] - b[k].cloud.points[i]).norm(), 1e-5);  // float32
      }
      ASSERT_EQ(a[k].imu.size(), b[k].imu.size()) << "scan " << k;
      for (size_t i = 0; i < a[k].imu.size(); ++i) {
        EXPECT_EQ(a[k].imu[i].t_ns, b[k].imu[i].t_ns);
        EXPECT_EQ(a[k].imu[i].gyro, b[k].imu[i].gyro);  // float64 in the message: exact
        EXPECT_EQ(a[k].imu[i].accel, b[k].imu[i].accel);
      }
    }
    const auto gt = read.GroundTruth();
    ASSERT_TRUE(gt);
    ASSERT_EQ(gt->size(), truth.GroundTruth()->size());
    EXPECT_LT(
        (gt->back().pose.translation() - truth.GroundTruth()->back().pose.translation()).norm(),
        1e-12);
  }
}

// Linking ctlio::io_rosbag is enough for OpenDataset to open a bag (dataset_file_opener.cc), as
// ctlio_odometry does without --format; a file that is not a bag gets the bag reader's error.
TEST(Rosbag, OpenDatasetOpensABag) {
  const fs::path d = testing::FreshTempDir("rosbag_open_dataset");
  const std::string bag = (d / "sim.bag").string();
  sim::SimulatedSource written(SmallSim());
  const size_t n = WriteRosbag(written, bag);
  const std::unique_ptr<DataSource> read = OpenDataset(bag);
  EXPECT_EQ(read->Name(), "rosbag:" + bag);
  EXPECT_EQ(read->NumScans(), n);
  EXPECT_THAT(read->ExtrinsicOrigin(), HasSubstr("/tf_static"));
  EXPECT_EQ(ReadAll(*read).size(), n);
  const std::string text = (d / "notes.txt").string();
  std::ofstream(text) << "not a bag\n";
  ExpectError([&] { OpenDataset(text); }, {"notes.txt", "not a ROS 1 bag"});
}

TEST(Rosbag, EveryDriverTimeFieldRoundTripsThroughPointCloud2) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::uniform_int_distribution<int64_t> dt(0, 99'999'999);
  for (const auto& v : fixtures::TimeVariants()) {
    SCOPED_TRACE(v.driver);
    PointCloud c;
    c.stamp_ns = 1700000000LL * 1000000000LL + 123456789LL;
    for (int i = 0; i < 300; ++i) {
      c.points.emplace_back(u(rng), u(rng), u(rng));
      c.times_ns.push_back(c.stamp_ns + dt(rng));
    }
    if (v.written.stamp_at == StampAt::kScanEnd) c.stamp_ns += 100'000'000;
    const auto msg = EncodePointCloud2(c, v.fields, v.point_step, v.written, "lidar");
    PointLayout layout;
    const PointCloud r = DecodePointCloud2(msg, {}, "", &layout);
    EXPECT_EQ(layout.convention.driver, v.driver);
    ASSERT_EQ(r.times_ns.size(), c.times_ns.size());
    for (size_t i = 0; i < c.size(); ++i) {
      EXPECT_LE(std::abs(double(r.times_ns[i] - c.times_ns[i])), v.tolerance_ns) << i;
    }
  }
}

// A bag with one Imu topic and the given PointCloud2 messages on /points.
void WriteBag(const std::string& path, const std::vector<sensor_msgs::PointCloud2>& clouds,
              const std::vector<std::string>& extra_cloud_topics = {}) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (int i = 1; i <= 30; ++i) {
    sensor_msgs::Imu m;
    m.header.stamp.fromNSec(uint64_t(i) * 10'000'000ULL);
    m.linear_acceleration.z = 9.81;
    bag.write("/imu", m.header.stamp, m);
  }
  for (const auto& c : clouds) bag.write("/points", ros::Time(0.2), c);
  for (const auto& t : extra_cloud_topics) bag.write(t, ros::Time(0.2), clouds.front());
}

sensor_msgs::PointCloud2 Cloud(std::vector<PointField> fields, uint32_t step) {
  PointCloud c;
  c.stamp_ns = 100'000'000;
  for (int i = 0; i < 10; ++i) {
    c.points.emplace_back(1.0 + i, 2.0, 0.5);
    c.times_ns.push_back(c.stamp_ns + i * 1000);
  }
  TimeConvention t;
  t.field = "t";
  return EncodePointCloud2(c, fields, step, t, "lidar");
}

TEST(Rosbag, BadBagsAndLayoutsGiveClearErrors) {
  const fs::path d = testing::FreshTempDir("rosbag_bad");
  const PointField x{"x", kFloat32, 0, 1}, y{"y", kFloat32, 4, 1}, z{"z", kFloat32, 8, 1};
  const std::string good = (d / "good.bag").string();
  WriteBag(good, {Cloud({x, y, z, {"t", kUInt32, 12, 1}}, 16)});

  // Truncated: the index at the end is gone.
  const std::string cut = (d / "cut.bag").string();
  {
    std::ifstream in(good, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    // Corrupted: the bag header record overwritten after the magic line.
    for (size_t i = 13; i < 200 && i < bytes.size(); ++i) bytes[i] = char(0xA5);
    std::ofstream((d / "corrupt.bag").string(), std::ios::binary) << bytes;
  }
  ExpectError([&] { RosbagSource s(cut); }, {"cut.bag", "truncated or corrupted"});
  ExpectError([&] { RosbagSource s((d / "corrupt.bag").string()); },
              {"corrupt.bag", "truncated or corrupted"});
  std::ofstream((d / "text.bag").string()) << "hello\n";
  ExpectError([&] { RosbagSource s((d / "text.bag").string()); }, {"text.bag", "not a ROS 1 bag"});
  ExpectError([&] { RosbagSource s((d / "missing.bag").string()); }, {"missing.bag", "not found"});

  // Topics: a missing one lists what the bag has; two PointCloud2 topics need a choice.
  RosbagOptions o;
  o.lidar_topic = "/velodyne_points";
  ExpectError([&] { RosbagSource s(good, o); },
              {"no topic '/velodyne_points'", "--lidar_topic", "/points (sensor_msgs/PointCloud2)",
               "/imu (sensor_msgs/Imu)"});
  o = {};
  o.imu_topic = "/points";
  ExpectError([&] { RosbagSource s(good, o); }, {"'/points' is sensor_msgs/PointCloud2, not"});
  const std::string two = (d / "two.bag").string();
  WriteBag(two, {Cloud({x, y, z, {"t", kUInt32, 12, 1}}, 16)}, {"/points2"});
  ExpectError([&] { RosbagSource s(two); },
              {"2 sensor_msgs/PointCloud2 topics", "/points", "/points2", "--lidar_topic"});
  o = {};
  o.lidar_topic = "/points2";
  EXPECT_EQ(RosbagSource(two, o).lidar_topic(), "/points2");

  // Layouts: errors name the bag, the topic, the message and the fields found.
  const std::string no_z = (d / "no_z.bag").string();
  WriteBag(no_z, {Cloud({x, y, {"t", kUInt32, 8, 1}}, 12)});
  ScanFrame f;
  ExpectError(
      [&] { RosbagSource(no_z).Next(&f); },
      {"no_z.bag", "topic /points, message 1", "no 'z' field", "x:float32 y:float32 t:uint32"});
  const std::string float_t = (d / "float_t.bag").string();
  auto bad = Cloud({x, y, z, {"t", kUInt32, 12, 1}}, 16);
  bad.fields[3].datatype = kFloat32;
  WriteBag(float_t, {bad});
  ExpectError([&] { RosbagSource(float_t).Next(&f); },
              {"float_t.bag", "message 1", "time field 't' is float32", "t:float32"});
  auto shortened = Cloud({x, y, z, {"t", kUInt32, 12, 1}}, 16);
  shortened.data.resize(shortened.data.size() - 5);
  const std::string short_bag = (d / "short.bag").string();
  WriteBag(short_bag, {shortened});
  ExpectError([&] { RosbagSource(short_bag).Next(&f); }, {"short.bag", "data holds 155 B"});

  // No extrinsic anywhere (different frames, no /tf_static, no preset): ImuFromLidar says what to
  // do; the scans still read.
  RosbagSource plain(good);
  ExpectError([&] { plain.ImuFromLidar(); },
              {"no lidar → IMU extrinsic", "extrinsic:", "--preset"});
  ASSERT_TRUE(plain.Next(&f));
  EXPECT_EQ(f.cloud.size(), 10u);
  EXPECT_EQ(f.imu.size(), 10u);  // 10 ms … 100 ms ≤ the scan end (100 ms + 9 µs)
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Overwrites the value of every header field `name=` (the bytes after it) with `value`.
std::string PatchField(std::string bytes, const std::string& name, const std::string& value) {
  size_t found = 0;
  for (size_t at = bytes.find(name + "="); at != std::string::npos;
       at = bytes.find(name + "=", at + 1), ++found) {
    bytes.replace(at + name.size() + 1, value.size(), value);
  }
  EXPECT_GT(found, 0u) << name;
  return bytes;
}

std::string U32(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string U64(uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }

// Corrupt lengths, offsets and counts are caught before the bag library sees them (it trusts
// them: a multi-GB allocation or a read outside the chunk), naming the bag and the byte.
TEST(Rosbag, BagStructureIsCheckedBeforeTheLibraryReadsIt) {
  const fs::path d = testing::FreshTempDir("rosbag_structure");
  const std::string good = (d / "good.bag").string();
  {
    sim::SimulatedSource source(SmallSim());
    WriteRosbag(source, good);
  }
  const std::string bytes = ReadBytes(good);
  auto expect_error = [&](const std::string& name, const std::string& corrupt,
                          const std::vector<std::string>& needles) {
    const std::string path = (d / name).string();
    std::ofstream(path, std::ios::binary) << corrupt;
    std::vector<std::string> all = {name, "not a valid ROS 1 bag"};
    all.insert(all.end(), needles.begin(), needles.end());
    ExpectError([&] { RosbagSource s(path); }, all);
  };
  // An uncompressed chunk declaring 4 GB (the library would allocate them).
  expect_error("chunk_size.bag", PatchField(bytes, "size", U32(0xFFFFFFF0u)),
               {"uncompressed chunk", "declares 4294967280"});
  expect_error("index_pos.bag", PatchField(bytes, "index_pos", U64(bytes.size() + 7)),
               {"index position is not a record"});
  expect_error("version.bag", PatchField(bytes, "ver", U32(2)), {"version is not 1"});
  // The first index entry's offset (header fields conn, count, op, ver; then the data length and
  // 12-byte entries: time, offset) pointing far beyond its chunk.
  std::string offset = bytes;
  const size_t ver = offset.find("ver=", offset.find(std::string("op=") + char(0x04)));
  ASSERT_NE(ver, std::string::npos);
  offset.replace(ver + 4 + 4 + 4 + 8, 4, U32(0xFFFFFF00u));
  expect_error("index_offset.bag", offset, {"index entry 0 points outside its chunk"});
  expect_error("truncated.bag", bytes.substr(0, bytes.size() - 3), {"does not fit"});
  // A message type whose md5sum is not the reader's: an error, not a null message.
  const std::string md5 = PatchField(bytes, "md5sum", "00000000");
  std::ofstream((d / "md5.bag").string(), std::ios::binary) << md5;
  ExpectError([&] { RosbagSource s((d / "md5.bag").string()); },
              {"md5.bag", "is not a sensor_msgs/", "md5sum 00000000"});
}

// Every input the bag fuzz target ever stopped on (fuzz/regressions/rosbag_*): a clear error or a
// bag read to the end, never a crash.
TEST(Rosbag, FuzzRegressionsGiveAnErrorOrRead) {
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(CTLIO_FUZZ_REGRESSIONS_DIR)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("rosbag_", 0) != 0) continue;
    ++files;
    try {
      RosbagSource source(e.path().string());
      ReadAll(source);
    } catch (const std::runtime_error& err) {
      EXPECT_THAT(err.what(), HasSubstr(e.path().string()));
    }
  }
  EXPECT_GT(files, 0u);
}

TEST(Rosbag, OdometryBagHoldsTheTrajectory) {
  const fs::path d = testing::FreshTempDir("rosbag_odometry");
  std::vector<StampedPose> trajectory;
  for (int k = 1; k <= 5; ++k) {
    const SE3 T(Eigen::AngleAxisd(0.3 * k, Vec3(1, 2, 3).normalized()).toRotationMatrix(),
                Vec3(k, -0.5 * k, 0.1));
    trajectory.push_back({int64_t(k) * 100'000'000, T});
  }
  const std::string path = (d / "trajectory.bag").string();
  WriteOdometryBag(path, trajectory);
  // Read back as ground truth: the reader takes nav_msgs/Odometry from a chosen topic.
  rosbag::Bag bag(path, rosbag::bagmode::Append);
  sensor_msgs::Imu imu;
  imu.header.stamp = ros::Time(0.05);
  bag.write("/imu", imu.header.stamp, imu);
  sensor_msgs::PointCloud2 cloud = Cloud(
      {{"x", kFloat32, 0, 1}, {"y", kFloat32, 4, 1}, {"z", kFloat32, 8, 1}, {"t", kUInt32, 12, 1}},
      16);
  bag.write("/points", ros::Time(0.2), cloud);
  bag.close();
  RosbagOptions o;
  o.ground_truth_topic = "/ctlio/odometry";
  const auto read = RosbagSource(path, o).GroundTruth();
  ASSERT_TRUE(read);
  ASSERT_EQ(read->size(), trajectory.size());
  for (size_t k = 0; k < trajectory.size(); ++k) {
    EXPECT_EQ((*read)[k].t_ns, trajectory[k].t_ns);
    EXPECT_LT(((*read)[k].pose.Matrix() - trajectory[k].pose.Matrix()).norm(), 1e-12);
  }
}

// With covariances, each message carries its own (row-major 36, as given).
TEST(Rosbag, OdometryBagHoldsThePoseCovariances) {
  const fs::path d = testing::FreshTempDir("rosbag_odometry_covariance");
  std::vector<StampedPose> trajectory(2);
  trajectory[0].t_ns = 100'000'000;
  trajectory[1].t_ns = 200'000'000;
  std::vector<std::array<double, 36>> covariances(2);
  for (size_t i = 0; i < 36; ++i) covariances[1][i] = 0.5 + double(i);
  const std::string path = (d / "trajectory.bag").string();
  WriteOdometryBag(path, trajectory, covariances);
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<nav_msgs::Odometry> read;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    const nav_msgs::Odometry::ConstPtr o = m.instantiate<nav_msgs::Odometry>();
    if (o) read.push_back(*o);
  }
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < 36; ++i) {
    EXPECT_EQ(read[0].pose.covariance[i], 0.0);
    EXPECT_EQ(read[1].pose.covariance[i], 0.5 + double(i));
  }
  covariances.pop_back();
  EXPECT_THROW(WriteOdometryBag(path, trajectory, covariances), std::invalid_argument);
}

TEST(Rosbag, AccelerometerScale) {
  const fs::path d = testing::FreshTempDir("rosbag_accel");
  const std::string path = (d / "g.bag").string();
  WriteBag(path, {Cloud({{"x", kFloat32, 0, 1},
                         {"y", kFloat32, 4, 1},
                         {"z", kFloat32, 8, 1},
                         {"t", kUInt32, 12, 1}},
                        16)});
  RosbagOptions o;
  o.accel_scale = 9.80665 / 9.81;  // the fixture writes 9.81
  RosbagSource s(path, o);
  ScanFrame f;
  ASSERT_TRUE(s.Next(&f));
  ASSERT_FALSE(f.imu.empty());
  EXPECT_NEAR(f.imu.front().accel.z(), 9.80665, 1e-12);
}

TEST(Rosbag, NoTimeFieldUsesTheAzimuth) {
  const fs::path d = testing::FreshTempDir("rosbag_azimuth");
  const PointField x{"x", kFloat32, 0, 1}, y{"y", kFloat32, 4, 1}, z{"z", kFloat32, 8, 1};
  const std::string path = (d / "xyz.bag").string();
  WriteBag(path, {Cloud({x, y, z, {"intensity", kFloat32, 12, 1}}, 16)});
  RosbagSource s(path);
  ScanFrame f;
  ASSERT_TRUE(s.Next(&f));
  ASSERT_TRUE(f.cloud.has_times());
  EXPECT_EQ(f.start_ns, 100'000'000);  // stamp at the scan start (the default)
  EXPECT_GE(f.end_ns, f.start_ns);
  EXPECT_LT(f.end_ns, f.start_ns + 100'000'000);
}

}  // namespace
}  // namespace ctlio::io
