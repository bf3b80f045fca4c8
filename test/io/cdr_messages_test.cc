// CDR (XCDR1) messages of ROS 2 bags: hand-built byte vectors in both byte orders checked field by
// field (alignment padding included), the encoder checked against the same bytes, round trips of
// every type, and every truncation and a few corruptions giving an error, not a crash.
#include "ctlio/io/cdr_messages.h"

#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::io::ros2 {
namespace {

using Bytes = std::vector<uint8_t>;

// A PointCloud2 in CDR_LE: stamp 10 s 20 ns, frame "ab" (string ends at body byte 15: one pad
// byte before height), one field "x" (two pad bytes after its name; three after datatype),
// point_step 4, row_step 8, 8 data bytes, dense.
// clang-format off
const Bytes kCloudLe = {
    0x00, 0x01, 0x00, 0x00,                 // encapsulation CDR_LE
    10, 0, 0, 0,  20, 0, 0, 0,              // stamp
    3, 0, 0, 0,  'a', 'b', 0,  /*pad*/ 0,   // frame_id
    1, 0, 0, 0,  2, 0, 0, 0,                // height, width
    1, 0, 0, 0,                             // fields: 1
    2, 0, 0, 0,  'x', 0,  /*pad*/ 0, 0,     // name
    0, 0, 0, 0,                             // offset
    7,  /*pad*/ 0, 0, 0,                    // datatype FLOAT32
    1, 0, 0, 0,                             // count
    0,  /*pad*/ 0, 0, 0,                    // is_bigendian
    4, 0, 0, 0,  8, 0, 0, 0,                // point_step, row_step
    8, 0, 0, 0,  1, 2, 3, 4, 5, 6, 7, 8,    // data
    1,                                      // is_dense
};

// A PoseStamped in CDR_BE: stamp 1 s 2 ns, frame "a" (two pad bytes before the float64s),
// position (1, 2, −0.5), orientation (x, y, z, w) = (0, 0, 0.25, 1).
const Bytes kPoseBe = {
    0x00, 0x00, 0x00, 0x00,                 // encapsulation CDR_BE
    0, 0, 0, 1,  0, 0, 0, 2,                // stamp
    0, 0, 0, 2,  'a', 0,  /*pad*/ 0, 0,     // frame_id
    0x3F, 0xF0, 0, 0, 0, 0, 0, 0,           // x = 1
    0x40, 0x00, 0, 0, 0, 0, 0, 0,           // y = 2
    0xBF, 0xE0, 0, 0, 0, 0, 0, 0,           // z = −0.5
    0, 0, 0, 0, 0, 0, 0, 0,                 // qx
    0, 0, 0, 0, 0, 0, 0, 0,                 // qy
    0x3F, 0xD0, 0, 0, 0, 0, 0, 0,           // qz = 0.25
    0x3F, 0xF0, 0, 0, 0, 0, 0, 0,           // qw = 1
};
// clang-format on

template <class M>
M Decode(const Bytes& b) {
  M m;
  DecodeCdr(b.data(), b.size(), "bag: topic /t, message 3: ", &m);
  return m;
}

// The message of `fn`'s std::runtime_error ("" if it did not throw).
std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(CdrMessages, DecodesAHandBuiltLittleEndianPointCloud2FieldByField) {
  const auto m = Decode<sensor_msgs::PointCloud2>(kCloudLe);
  EXPECT_EQ(m.header.stamp.sec, 10u);
  EXPECT_EQ(m.header.stamp.nsec, 20u);
  EXPECT_EQ(m.header.frame_id, "ab");
  EXPECT_EQ(m.height, 1u);
  EXPECT_EQ(m.width, 2u);
  ASSERT_EQ(m.fields.size(), 1u);
  EXPECT_EQ(m.fields[0].name, "x");
  EXPECT_EQ(m.fields[0].offset, 0u);
  EXPECT_EQ(m.fields[0].datatype, 7);
  EXPECT_EQ(m.fields[0].count, 1u);
  EXPECT_FALSE(m.is_bigendian);
  EXPECT_EQ(m.point_step, 4u);
  EXPECT_EQ(m.row_step, 8u);
  EXPECT_EQ(m.data, (Bytes{1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_TRUE(m.is_dense);
}

TEST(CdrMessages, EncoderWritesTheHandBuiltBytes) {
  EXPECT_EQ(EncodeCdr(Decode<sensor_msgs::PointCloud2>(kCloudLe)), kCloudLe);
  EXPECT_EQ(EncodeCdr(Decode<geometry_msgs::PoseStamped>(kPoseBe), CdrEndian::kBig), kPoseBe);
}

TEST(CdrMessages, DecodesAHandBuiltBigEndianPoseStamped) {
  const auto m = Decode<geometry_msgs::PoseStamped>(kPoseBe);
  EXPECT_EQ(m.header.stamp.sec, 1u);
  EXPECT_EQ(m.header.stamp.nsec, 2u);
  EXPECT_EQ(m.header.frame_id, "a");
  EXPECT_EQ(m.pose.position.x, 1.0);
  EXPECT_EQ(m.pose.position.y, 2.0);
  EXPECT_EQ(m.pose.position.z, -0.5);
  EXPECT_EQ(m.pose.orientation.x, 0.0);
  EXPECT_EQ(m.pose.orientation.y, 0.0);
  EXPECT_EQ(m.pose.orientation.z, 0.25);
  EXPECT_EQ(m.pose.orientation.w, 1.0);
}

sensor_msgs::Imu SomeImu() {
  sensor_msgs::Imu m;
  m.header.stamp.sec = 1700000000;
  m.header.stamp.nsec = 999999999;
  m.header.frame_id = "imu_link";
  m.orientation.x = 0.1;
  m.orientation.w = -0.7;
  for (int i = 0; i < 9; ++i) {
    m.orientation_covariance[i] = -1.0 - i;
    m.angular_velocity_covariance[i] = 1e-3 * i;
    m.linear_acceleration_covariance[i] = 2e-3 * i;
  }
  m.angular_velocity.x = 0.01;
  m.angular_velocity.y = -0.02;
  m.angular_velocity.z = 0.03;
  m.linear_acceleration.x = 0.1;
  m.linear_acceleration.y = 0.2;
  m.linear_acceleration.z = 9.80665;
  return m;
}

tf2_msgs::TFMessage SomeTf() {
  tf2_msgs::TFMessage m;
  for (int i = 0; i < 2; ++i) {
    geometry_msgs::TransformStamped t;
    t.header.stamp.sec = 5 + i;
    t.header.frame_id = i == 0 ? "base" : "";  // the empty string: length 1, one NUL
    t.child_frame_id = "os_lidar" + std::to_string(i);
    t.transform.translation.x = 0.5 * i;
    t.transform.translation.z = -0.25;
    t.transform.rotation.y = 0.6;
    t.transform.rotation.w = 0.8;
    m.transforms.push_back(t);
  }
  return m;
}

nav_msgs::Odometry SomeOdometry() {
  nav_msgs::Odometry m;
  m.header.stamp.sec = 42;
  m.header.stamp.nsec = 7;
  m.header.frame_id = "world";
  m.child_frame_id = "os";
  m.pose.pose.position.x = 3.5;
  m.pose.pose.orientation.z = 1.0;
  for (int i = 0; i < 36; ++i) {
    m.pose.covariance[i] = i;
    m.twist.covariance[i] = -i;
  }
  m.twist.twist.linear.y = 1.25;
  m.twist.twist.angular.z = -0.125;
  return m;
}

TEST(CdrMessages, RoundTripsEveryTypeInBothByteOrders) {
  for (CdrEndian e : {CdrEndian::kLittle, CdrEndian::kBig}) {
    SCOPED_TRACE(e == CdrEndian::kLittle ? "little" : "big");
    EXPECT_EQ(Decode<sensor_msgs::Imu>(EncodeCdr(SomeImu(), e)), SomeImu());
    EXPECT_EQ(Decode<tf2_msgs::TFMessage>(EncodeCdr(SomeTf(), e)), SomeTf());
    EXPECT_EQ(Decode<nav_msgs::Odometry>(EncodeCdr(SomeOdometry(), e)), SomeOdometry());
    const auto cloud = Decode<sensor_msgs::PointCloud2>(kCloudLe);
    EXPECT_EQ(Decode<sensor_msgs::PointCloud2>(EncodeCdr(cloud, e)), cloud);
    const auto pose = Decode<geometry_msgs::PoseStamped>(kPoseBe);
    EXPECT_EQ(Decode<geometry_msgs::PoseStamped>(EncodeCdr(pose, e)), pose);
  }
  // Byte order changes the bytes, not the values: the Imu's body differs between the two.
  EXPECT_NE(EncodeCdr(SomeImu(), CdrEndian::kLittle), EncodeCdr(SomeImu(), CdrEndian::kBig));
}

template <class M>
void ExpectEveryTruncationFails(const Bytes& full, const std::string& type) {
  for (size_t n = 0; n < full.size(); ++n) {
    const Bytes cut(full.begin(), full.begin() + n);
    const std::string e = ErrorOf([&] { Decode<M>(cut); });
    ASSERT_NE(e.find("bag: topic /t, message 3: corrupt " + type + " message: "), std::string::npos)
        << type << " cut at " << n << " of " << full.size() << ": '" << e << "'";
  }
}

TEST(CdrMessages, EveryTruncationIsAnErrorNamingTheMessage) {
  // Padding at the end may be absent, so only the cuts inside the last field count: the
  // messages below end in a full field (no trailing padding).
  ExpectEveryTruncationFails<sensor_msgs::PointCloud2>(kCloudLe, "sensor_msgs/msg/PointCloud2");
  ExpectEveryTruncationFails<geometry_msgs::PoseStamped>(kPoseBe, "geometry_msgs/msg/PoseStamped");
  ExpectEveryTruncationFails<sensor_msgs::Imu>(EncodeCdr(SomeImu()), "sensor_msgs/msg/Imu");
  ExpectEveryTruncationFails<tf2_msgs::TFMessage>(EncodeCdr(SomeTf(), CdrEndian::kBig),
                                                  "tf2_msgs/msg/TFMessage");
  ExpectEveryTruncationFails<nav_msgs::Odometry>(EncodeCdr(SomeOdometry()),
                                                 "nav_msgs/msg/Odometry");
}

TEST(CdrMessages, CountsAndLengthsPastTheEndAreErrorsBeforeAllocation) {
  Bytes b = kCloudLe;
  b[64] = b[65] = b[66] = b[67] = 0xFF;  // data: 4294967295 bytes
  EXPECT_NE(ErrorOf([&] {
              Decode<sensor_msgs::PointCloud2>(b);
            }).find("data: 4294967295 elements of at least 1 bytes, 9 bytes left (at byte 68)"),
            std::string::npos);
  b = kCloudLe;
  b[28] = 0xF0;  // fields: 240 PointFields in 49 bytes
  EXPECT_NE(ErrorOf([&] { Decode<sensor_msgs::PointCloud2>(b); }).find("fields: 240 elements"),
            std::string::npos);
  b = kCloudLe;
  b[12] = 200;  // frame_id: 200 bytes
  EXPECT_NE(ErrorOf([&] {
              Decode<sensor_msgs::PointCloud2>(b);
            }).find("header.frame_id: needs 200 bytes, 61 left (at byte 16)"),
            std::string::npos);
  Bytes tf = EncodeCdr(SomeTf());
  tf[4] = tf[5] = tf[6] = tf[7] = 0xFF;
  EXPECT_NE(ErrorOf([&] { Decode<tf2_msgs::TFMessage>(tf); }).find("transforms: 4294967295"),
            std::string::npos);
}

TEST(CdrMessages, RejectsForeignEncodingsBadValuesAndLeftovers) {
  Bytes b = kCloudLe;
  b[1] = 0x07;  // XCDR2 little-endian delimited: not what rosbag2 records for these types
  EXPECT_NE(ErrorOf([&] {
              Decode<sensor_msgs::PointCloud2>(b);
            }).find("encapsulation 0,7 is not CDR_LE (0,1) or CDR_BE (0,0)"),
            std::string::npos);
  b = kCloudLe;
  b.back() = 2;  // is_dense
  EXPECT_NE(ErrorOf([&] {
              Decode<sensor_msgs::PointCloud2>(b);
            }).find("is_dense: boolean byte 2 is not 0 or 1"),
            std::string::npos);
  b = kCloudLe;
  b[18] = 'c';  // frame_id's NUL
  EXPECT_NE(ErrorOf([&] { Decode<sensor_msgs::PointCloud2>(b); }).find("not NUL-terminated"),
            std::string::npos);
  Bytes pose = kPoseBe;
  pose[4] = 0x80;  // sec < 0
  EXPECT_NE(ErrorOf([&] { Decode<geometry_msgs::PoseStamped>(pose); }).find("before 1970"),
            std::string::npos);
  pose = kPoseBe;
  pose[8] = 0x40;  // nanosec ≥ 10⁹
  EXPECT_NE(ErrorOf([&] { Decode<geometry_msgs::PoseStamped>(pose); }).find("nanosec"),
            std::string::npos);
  // Up to 7 bytes of trailing alignment padding are accepted, 8 are left over.
  pose = kPoseBe;
  pose.resize(pose.size() + 7, 0);
  EXPECT_EQ(Decode<geometry_msgs::PoseStamped>(pose), Decode<geometry_msgs::PoseStamped>(kPoseBe));
  pose.push_back(0);
  EXPECT_NE(ErrorOf([&] {
              Decode<geometry_msgs::PoseStamped>(pose);
            }).find("8 bytes left over after the message"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              Decode<sensor_msgs::Imu>(Bytes{0, 1});
            }).find("2 bytes, shorter than the 4-byte encapsulation header"),
            std::string::npos);
}

TEST(CdrMessages, EncodingATimePast2038Throws) {
  geometry_msgs::PoseStamped p;
  p.header.stamp.sec = uint32_t(INT32_MAX) + 1u;
  EXPECT_NE(ErrorOf([&] { EncodeCdr(p); }).find("does not fit ROS 2's int32 seconds"),
            std::string::npos);
}

TEST(CdrMessages, MapsTypeNamesBetweenRos1AndRos2) {
  EXPECT_EQ(Ros1TypeName("sensor_msgs/msg/PointCloud2"), "sensor_msgs/PointCloud2");
  EXPECT_EQ(Ros2TypeName("tf2_msgs/TFMessage"), "tf2_msgs/msg/TFMessage");
  EXPECT_EQ(Ros1TypeName("foo"), "foo");
  EXPECT_EQ(Ros1TypeName("a/msg/b/c"), "a/msg/b/c");
  EXPECT_EQ(Ros2TypeName("a/b/c"), "a/b/c");
}

}  // namespace
}  // namespace ctlio::io::ros2
