// The shared validation layer (point_layout_check.h, ros_wire_check.h, extrinsic_check.h) and the
// bag's recovery of unusable scans: each defect class in every layout it applies to, each error
// naming its source (file, or bag + topic + message index) and each recovery counted.
//   * point layouts: point_step 0, a field past point_step, data length ≠ height × row_step,
//     row_step shorter than a row, a huge width over a few bytes — PointCloud2 (decoded and in a
//     bag), PCD and PLY (where the file can express the defect) give the same answer;
//   * lengths and counts inside a bag message that passes the record-structure check: refused
//     before the deserialiser allocates from them;
//   * /tf_static extrinsics: NaN, Inf, zero or non-unit quaternions are errors naming the message;
//   * bag scans that are empty, all non-finite or all at one instant are handed on and counted.
#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "common/warning_sink.h"
#include "ctlio/io/extrinsic_check.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/io/point_layout_check.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/ros_wire_check.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/warning_limiter.h"
#include "io/small_pointcloud2.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::ctlio::testing::ExpectError;
using ::testing::HasSubstr;

constexpr int64_t kStamp = 200'000'000;  // 0.2 s

// 10 points x y z float32 + t uint32 (16 B), t = 0, 1 … 9 µs after the stamp.
sensor_msgs::PointCloud2 GoodCloud(int64_t stamp_ns = kStamp, int n = 10) {
  return testing::SmallPointCloud2(stamp_ns, n);
}

struct TfEdge {
  double qw, qx, qy, qz, tx, ty, tz;
};

// A bag: IMU at 100 Hz from 10 ms (frame "imu"), the clouds on /points, optionally one /tf_static
// message imu → lidar.
void WriteBag(const std::string& path, const std::vector<sensor_msgs::PointCloud2>& clouds,
              const std::optional<TfEdge>& tf = std::nullopt) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  if (tf) {
    tf2_msgs::TFMessage m;
    geometry_msgs::TransformStamped e;
    e.header.frame_id = "imu";
    e.child_frame_id = "lidar";
    e.transform.rotation.w = tf->qw;
    e.transform.rotation.x = tf->qx;
    e.transform.rotation.y = tf->qy;
    e.transform.rotation.z = tf->qz;
    e.transform.translation.x = tf->tx;
    e.transform.translation.y = tf->ty;
    e.transform.translation.z = tf->tz;
    m.transforms.push_back(e);
    bag.write("/tf_static", ros::Time(0.001), m);
  }
  int64_t last = kStamp;
  for (const auto& c : clouds) last = std::max<int64_t>(last, int64_t(c.header.stamp.toNSec()));
  for (int64_t t = 10'000'000; t <= last + 200'000'000; t += 10'000'000) {
    sensor_msgs::Imu m;
    m.header.stamp.fromNSec(uint64_t(t));
    m.header.frame_id = "imu";
    m.linear_acceleration.z = 9.81;
    bag.write("/imu", m.header.stamp, m);
  }
  for (const auto& c : clouds) bag.write("/points", c.header.stamp, c);
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string Serialize(const sensor_msgs::PointCloud2& m) {
  std::string bytes(ros::serialization::serializationLength(m), '\0');
  ros::serialization::OStream out(reinterpret_cast<uint8_t*>(bytes.data()), uint32_t(bytes.size()));
  ros::serialization::serialize(out, m);
  return bytes;
}

// Byte offsets inside a serialised PointCloud2 (ROS 1 wire format, no padding).
size_t FieldsCountOffset(const sensor_msgs::PointCloud2& m) {
  return 4 + 8 + 4 + m.header.frame_id.size() + 8;
}
size_t DataLengthOffset(const sensor_msgs::PointCloud2& m) {
  size_t at = FieldsCountOffset(m) + 4;
  for (const auto& f : m.fields) at += 4 + f.name.size() + 9;
  return at + 1 + 4 + 4;
}

void PutU32(std::string* bytes, size_t at, uint32_t v) { std::memcpy(bytes->data() + at, &v, 4); }

// ---------------------------------------------------------------------------------------------
// Point layouts

TEST(PointLayoutCheck, EveryDefectOfAPointCloud2IsAnErrorNamingIt) {
  ScanFrame f;
  struct Case {
    const char* name;
    std::function<void(sensor_msgs::PointCloud2*)> corrupt;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"point_step_0", [](auto* m) { m->point_step = 0; }, {"point_step is 0 for 10 points"}},
      // (row_step kept consistent so that the field check is the one that answers)
      {"field_past_step",
       [](auto* m) { m->fields[3].offset = 14; },
       {"field 't' ends past the point step of 16 B", "at byte 14 end at byte 18"}},
      {"field_count_past_step",
       [](auto* m) { m->fields[0].count = 5; },
       {"field 'x' ends past the point step of 16 B"}},
      {"unknown_datatype",
       [](auto* m) { m->fields[3].datatype = 42; },
       {"field 't' has an unknown datatype"}},
      {"data_longer",
       [](auto* m) { m->data.resize(m->data.size() + 5); },
       {"data holds 165 B; 1 × 10 points of 16 B need 160 B"}},
      {"data_shorter",
       [](auto* m) { m->data.resize(m->data.size() - 5); },
       {"data holds 155 B; 1 × 10 points of 16 B need 160 B"}},
      {"width_times_height",
       [](auto* m) { m->height = 2; },
       {"data holds 160 B; 2 × 10 points of 16 B need 320 B"}},
      {"row_step_short",
       [](auto* m) { m->row_step = 8; },
       {"row_step 8 B is shorter than a row of 10 points × 16 B = 160 B"}},
      {"row_step_long",
       [](auto* m) { m->row_step = 170; },
       {"data holds 160 B; 1 × 10 points of 16 B in rows of 170 B need 170 B"}},
      {"huge_width",
       [](auto* m) {
         m->width = 200'000'000;
         m->row_step = 3'200'000'000u;
       },
       {"data holds 160 B; 1 × 200000000 points of 16 B need 3200000000 B"}},
      {"huge_point_step",
       [](auto* m) {
         m->point_step = 0x80000000u;
         m->width = 1;
         m->row_step = 0x80000000u;
       },
       {"point_step 2147483648 B exceeds 1048576 B"}},
      {"huge_field_count",
       [](auto* m) { m->fields[3].count = 0xFFFFFFFFu; },
       {"field 't' has count 4294967295"}},
  };
  const fs::path d = testing::FreshTempDir("layout_check_bag");
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    sensor_msgs::PointCloud2 m = GoodCloud();
    c.corrupt(&m);
    // Decoded directly, with the caller's prefix …
    std::vector<std::string> direct = {"direct: "};
    direct.insert(direct.end(), c.needles.begin(), c.needles.end());
    const auto t0 = std::chrono::steady_clock::now();
    ExpectError([&] { DecodePointCloud2(m, {}, "direct: "); }, direct);
    // … and as the second scan of a bag: the error names the bag, the topic and the message.
    const std::string bag = (d / (std::string(c.name) + ".bag")).string();
    WriteBag(bag, {GoodCloud(kStamp - 100'000'000), m});
    std::vector<std::string> in_bag = {std::string(c.name) + ".bag", "topic /points, message 2"};
    in_bag.insert(in_bag.end(), c.needles.begin(), c.needles.end());
    ExpectError(
        [&] {
          RosbagSource s(bag);
          while (s.Next(&f)) {
          }
        },
        in_bag);
    // Refused from the sizes, not after allocating or walking what the header declares.
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  }
}

TEST(PointLayoutCheck, ValidLayoutsStillDecode) {
  // Rows with padding (row_step > width × point_step), several rows, an empty cloud.
  sensor_msgs::PointCloud2 m = GoodCloud();
  m.height = 2;
  m.width = 5;
  m.row_step = 5 * 16 + 3;
  std::vector<uint8_t> padded;
  for (int r = 0; r < 2; ++r) {
    padded.insert(padded.end(), m.data.begin() + r * 80, m.data.begin() + (r + 1) * 80);
    padded.insert(padded.end(), 3, 0xEE);
  }
  m.data = padded;
  const PointCloud c = DecodePointCloud2(m, {}, "");
  ASSERT_EQ(c.size(), 10u);
  EXPECT_FLOAT_EQ(float(c.points[9].x()), 10.0f);
  EXPECT_EQ(c.times_ns[9], kStamp + 9000);
  sensor_msgs::PointCloud2 empty = GoodCloud();
  empty.width = 0;
  empty.row_step = 0;
  empty.data.clear();
  EXPECT_EQ(DecodePointCloud2(empty, {}, "").size(), 0u);
  empty.point_step = 0;  // no points: no step needed
  EXPECT_EQ(DecodePointCloud2(empty, {}, "").size(), 0u);
}

// PCD and PLY compute offsets and the step from their headers (a field past the step or a step of
// 0 cannot be written); the byte count is theirs to get wrong, and gets the PointCloud2 answer.
TEST(PointLayoutCheck, PcdAndPlyGiveTheSameAnswerToTheSameByteCount) {
  const fs::path d = testing::FreshTempDir("layout_check_files");
  const std::string pcd_head =
      "VERSION .7\nFIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n";
  const std::string ply_head =
      "ply\nformat binary_little_endian 1.0\nelement vertex N\nproperty float x\n"
      "property float y\nproperty float z\nproperty uint t\nend_header\n";
  const std::string ten(160, '\x01');
  auto pcd = [&](const std::string& name, const std::string& points, const std::string& data) {
    const std::string p = (d / name).string();
    std::ofstream(p, std::ios::binary)
        << pcd_head << "WIDTH " << points << "\nHEIGHT 1\nPOINTS " << points << "\nDATA binary\n"
        << data;
    return p;
  };
  auto ply = [&](const std::string& name, const std::string& points, const std::string& data) {
    std::string head = ply_head;
    head.replace(head.find(" N\n"), 3, " " + points + "\n");
    const std::string p = (d / name).string();
    std::ofstream(p, std::ios::binary) << head << data;
    return p;
  };
  struct Case {
    std::string name, points, data, needle;
  };
  const std::vector<Case> cases = {
      {"short", "10", ten.substr(0, 155), "holds 155 B; 1 × 10 points of 16 B need 160 B"},
      {"long", "10", ten + "\x07\x07\x07\x07\x07", "holds 165 B; 1 × 10 points of 16 B need 160 B"},
      {"huge_width", "200000000", ten,
       "holds 160 B; 1 × 200000000 points of 16 B need 3200000000 B"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string a = pcd(c.name + ".pcd", c.points, c.data);
    ExpectError([&] { ReadPcd(a); }, {c.name + ".pcd", "binary data " + c.needle});
    const std::string b = ply(c.name + ".ply", c.points, c.data);
    ExpectError([&] { ReadPly(b); }, {c.name + ".ply", "binary vertex data " + c.needle});
    // The same defect in a PointCloud2: the same sentence.
    sensor_msgs::PointCloud2 m = GoodCloud();
    m.width = uint32_t(std::stoul(c.points));
    m.row_step = m.width * 16;
    m.data.assign(c.data.begin(), c.data.end());
    ExpectError([&] { DecodePointCloud2(m, {}, ""); }, {"data " + c.needle});
  }
  // Zero padding after the records (PCL's writer) is still accepted.
  const std::string padded = pcd("padded.pcd", "10", ten + std::string(7, '\0'));
  EXPECT_EQ(ReadPcd(padded).size(), 10u);
}

// A corrupt length or count inside a message of an uncompressed bag (the record structure is
// intact) is refused before roscpp's deserialiser allocates from it.
TEST(PointLayoutCheck, CorruptLengthsInsideABagMessageAreRefusedBeforeAllocating) {
  const fs::path d = testing::FreshTempDir("wire_check_bag");
  sensor_msgs::PointCloud2 m = GoodCloud();
  m.header.frame_id = "lidar_marker_frame";  // locates the message in the file
  const std::string good = (d / "good.bag").string();
  WriteBag(good, {m});
  const std::string bytes = ReadBytes(good);
  const std::string wire = Serialize(m);
  const size_t at = bytes.find(wire);
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(bytes.find(wire, at + 1), std::string::npos);
  struct Case {
    std::string name;
    size_t offset;
    uint32_t value;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"data_length", DataLengthOffset(m), 0xFFFFFFF0u, {"data count 4294967280 needs at least"}},
      {"fields_count", FieldsCountOffset(m), 0x7FFFFFFFu, {"fields count 2147483647 needs"}},
      {"frame_id_length", 4 + 8, 0xFFFFFF00u, {"header frame_id needs 4294967040 B"}},
      {"data_length_short", DataLengthOffset(m), 100, {"B after the message's last field"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string corrupt = bytes;
    PutU32(&corrupt, at + c.offset, c.value);
    const std::string path = (d / (c.name + ".bag")).string();
    std::ofstream(path, std::ios::binary) << corrupt;
    std::vector<std::string> needles = {c.name + ".bag", "topic /points, message 1",
                                        "corrupt sensor_msgs/PointCloud2 message"};
    needles.insert(needles.end(), c.needles.begin(), c.needles.end());
    ExpectError([&] { RosbagSource s(path); }, needles);
  }
  // The walk itself on the unmodified message, and on every truncation of it: never a read past
  // the end (the sanitizer build runs this too).
  const auto* p = reinterpret_cast<const uint8_t*>(wire.data());
  CheckPointCloud2Wire(p, wire.size(), "");
  for (size_t n = 0; n < wire.size(); ++n) {
    EXPECT_THROW(CheckPointCloud2Wire(p, n, ""), std::runtime_error) << n;
  }
}

// ---------------------------------------------------------------------------------------------
// Extrinsics

TEST(ExtrinsicCheck, TfStaticWithANonFiniteOrNonUnitTransformIsAnErrorNamingTheMessage) {
  const fs::path d = testing::FreshTempDir("extrinsic_tf_static");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::string name;
    TfEdge tf;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {"nan_w", {nan, 0, 0, 0, 0, 0, 0}, "quaternion is not finite"},
      {"nan_x", {1, nan, 0, 0, 0, 0, 0}, "quaternion is not finite"},
      {"inf_z", {1, 0, 0, inf, 0, 0, 0}, "quaternion is not finite"},
      {"nan_t", {1, 0, 0, 0, 0.1, nan, 0}, "translation is not finite"},
      {"inf_t", {1, 0, 0, 0, -inf, 0, 0}, "translation is not finite"},
      {"zero_q", {0, 0, 0, 0, 0.1, 0, 0}, "|q|^2 = 0, outside 1 ± 0.01"},
      {"long_q", {1.2, 0, 0, 0, 0, 0, 0}, "|q|^2 = 1.44"},
      {"short_q", {0.7, 0, 0, 0.1, 0, 0, 0}, "|q|^2 = 0.5"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string bag = (d / (c.name + ".bag")).string();
    WriteBag(bag, {GoodCloud()}, c.tf);
    ExpectError([&] { RosbagSource s(bag); }, {c.name + ".bag", "topic /tf_static, message 1",
                                               "transform imu → lidar", c.needle});
  }
  // Within tf2's tolerance (|q|² = 1.004, printed with 3 decimals): accepted and normalised.
  const std::string ok = (d / "ok.bag").string();
  WriteBag(ok, {GoodCloud()}, TfEdge{0.707, 0, 0, 0.710, 0.1, 0.2, 0.3});
  RosbagSource s(ok);
  const SE3 T = s.ImuFromLidar();
  const Mat3 C = T.Matrix().topLeftCorner(3, 3);
  EXPECT_NEAR(C.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(T.translation().y(), 0.2, 1e-15);
  EXPECT_THAT(s.ExtrinsicOrigin(), HasSubstr("/tf_static"));
}

TEST(ExtrinsicCheck, CheckedExtrinsicRefusesWhatEigenWouldNormaliseSilently) {
  ExpectError([] { CheckedExtrinsic(0, 0, 0, 0, Vec3::Zero(), "file.yaml: "); },
              {"file.yaml: extrinsic quaternion is not a rotation", "w x y z = 0 0 0 0"});
  // The edges of the tolerance: |q|² = 1 ± 0.0099 accepted, 1 ± 0.0101 refused.
  EXPECT_NO_THROW(CheckedExtrinsic(std::sqrt(1.0099), 0, 0, 0, Vec3::Zero(), ""));
  EXPECT_NO_THROW(CheckedExtrinsic(std::sqrt(0.9901), 0, 0, 0, Vec3::Zero(), ""));
  EXPECT_THROW(CheckedExtrinsic(std::sqrt(1.0101), 0, 0, 0, Vec3::Zero(), ""), std::runtime_error);
  EXPECT_THROW(CheckedExtrinsic(std::sqrt(0.9899), 0, 0, 0, Vec3::Zero(), ""), std::runtime_error);
  const SE3 T = CheckedExtrinsic(0, 0, 0, 2.0 / std::sqrt(4.02), Vec3(1, 2, 3), "");
  EXPECT_LT(
      (T.Matrix().topLeftCorner<3, 3>() - Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix())
          .norm(),
      1e-12);
}

// ---------------------------------------------------------------------------------------------
// Recovery of unusable bag scans

using ::ctlio::testing::WarningSink;

TEST(BagRecovery, EmptyAllNonFiniteAndZeroDurationScansAreHandedOnAndCounted) {
  const fs::path d = testing::FreshTempDir("bag_recovery");
  // 20 Hz: the nominal interval follows the bag's stamp spacing, not the 0.1 s default.
  const int64_t period = 50'000'000;
  std::vector<sensor_msgs::PointCloud2> clouds;
  for (int k = 0; k < 6; ++k) clouds.push_back(GoodCloud(kStamp + k * period));
  // Message 2: no points at all.
  clouds[1].width = 0;
  clouds[1].row_step = 0;
  clouds[1].data.clear();
  // Message 3: every coordinate NaN.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < 10; ++i) std::memcpy(clouds[2].data.data() + 16 * i, &nan, 4);
  // Message 5: every point at the stamp (t = 0).
  for (size_t i = 0; i < 10; ++i) std::memset(clouds[4].data.data() + 16 * i + 12, 0, 4);
  const std::string bag = (d / "unusable.bag").string();
  WriteBag(bag, clouds);

  WarningSink sink;
  RosbagSource s(bag);
  std::vector<ScanFrame> frames;
  ScanFrame f;
  while (s.Next(&f)) frames.push_back(f);
  ASSERT_EQ(frames.size(), 6u);  // nothing aborted, nothing skipped from the sequence
  EXPECT_EQ(s.unusable_scans(), 2u);
  // Message 5 has points at distinct azimuths: its times are recovered from them (issue 40,
  // point_time_check.h) rather than the scan being handed on with a nominal interval.
  EXPECT_EQ(s.retimed_scans(), 1u);
  EXPECT_EQ(frames[4].start_ns, kStamp + 4 * period);
  EXPECT_GT(frames[4].end_ns, frames[4].start_ns);
  EXPECT_LT(frames[4].end_ns, kStamp + 5 * period);
  for (int k : {1, 2}) {
    SCOPED_TRACE(k);
    const int64_t stamp = kStamp + k * period;
    EXPECT_EQ(frames[k].start_ns, stamp);
    EXPECT_EQ(frames[k].end_ns, stamp + period - 1);  // the nominal interval
    EXPECT_EQ(frames[k].index, size_t(k));
  }
  EXPECT_TRUE(frames[1].cloud.points.empty());
  EXPECT_TRUE(frames[2].cloud.points.empty());
  EXPECT_EQ(frames[2].cloud.dropped_non_finite, 10u);
  EXPECT_EQ(frames[4].cloud.size(), 10u);  // points kept, times from the azimuth
  for (int k : {0, 3, 5}) {
    EXPECT_EQ(frames[k].cloud.size(), 10u);
    EXPECT_EQ(frames[k].end_ns, kStamp + k * period + 9000);
  }
  // Every scan's IMU is handed on (10 ms IMU: the unusable scans carry theirs too).
  for (size_t k = 1; k < frames.size(); ++k) EXPECT_FALSE(frames[k].imu.empty()) << k;
  // Warnings name the bag, the topic and the message; the total is reported at the end.
  const std::vector<std::string> lines = sink.lines();
  for (const std::string& needle :
       {std::string("unusable.bag: topic /points, message 2: 0 usable points (0 non-finite), none"),
        std::string("unusable.bag: topic /points, message 3: 0 usable points (10 non-finite)"),
        std::string("unusable.bag: topic /points, message 5: time field 't' (ns since the stamp, "
                    "stamp at scan start, Ouster): all 10 points at the scan stamp; times "
                    "recovered from the azimuth instead"),
        std::string("2 unusable scan(s)")}) {
    bool found = false;
    for (const std::string& l : lines) found = found || l.find(needle) != std::string::npos;
    EXPECT_TRUE(found) << needle;
  }
}

// The bag's IMU stream (BagSource::Impl::AddImu, shared with ROS 2 bags): a repeated stamp is
// dropped and counted among the run's input defects (an error under --strict), as in the folder
// readers; a stamp going backwards is an error naming the topic and message.
TEST(BagImu, ADuplicateStampIsCountedAndTimeBackwardsIsAnErrorNamingTheMessage) {
  const fs::path d = testing::FreshTempDir("bag_imu");
  auto write = [&](const std::string& name, int64_t sixth_ns) {
    const std::string path = (d / name).string();
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int k = 1; k <= 40; ++k) {
      sensor_msgs::Imu m;
      m.header.stamp.fromNSec(uint64_t(k == 6 ? sixth_ns : k * 10'000'000LL));
      m.header.frame_id = "imu";
      m.linear_acceleration.z = 9.81;
      bag.write("/imu", ros::Time(0.001 * k), m);
    }
    const sensor_msgs::PointCloud2 c = GoodCloud();
    bag.write("/points", c.header.stamp, c);
    return path;
  };
  const std::string dup = write("dup.bag", 50'000'000);  // the fifth sample's stamp again
  {
    WarningSink sink;
    RosbagSource s(dup);
    ScanFrame f;
    while (s.Next(&f)) {
    }
    const auto defects = s.InputDefects();
    bool counted = false;
    for (const InputDefect& x : defects) {
      if (x.kind != "duplicate IMU time") continue;
      counted = true;
      EXPECT_EQ(x.count, 1u);
      EXPECT_THAT(x.first, HasSubstr("dup.bag: topic /imu, message 6"));
    }
    EXPECT_TRUE(counted) << "not among the input defects";
  }
  WarningLimiter::SetStrict(true);
  ExpectError(
      [&] {
        RosbagSource s(dup);
        ScanFrame f;
        while (s.Next(&f)) {
        }
      },
      {"dup.bag: topic /imu, message 6", "duplicate IMU time", "--strict"});
  WarningLimiter::SetStrict(false);
  const std::string back = write("back.bag", 45'000'000);
  ExpectError(
      [&] {
        RosbagSource s(back);
        ScanFrame f;
        while (s.Next(&f)) {
        }
      },
      {"back.bag: topic /imu, message 6", "IMU time goes backwards"});
}

}  // namespace
}  // namespace ctlio::io
