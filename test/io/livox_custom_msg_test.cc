// livox_ros_driver2/CustomMsg (livox_custom_msg.h): the md5sums recomputed as ROS computes them,
// serialization round trip, times timebase + offset_time, the conversion's time detection, and
// the wire check of a corrupt or truncated message.
#include "ctlio/io/livox_custom_msg.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <boost/uuid/detail/md5.hpp>
#include <cstdio>

#include "common/expect_error.h"
#include "ctlio/io/pointcloud2.h"

namespace ctlio::io::livox {
namespace {

using ::ctlio::testing::ExpectError;

std::string Md5(const std::string& text) {
  boost::uuids::detail::md5 h;
  h.process_bytes(text.data(), text.size());
  boost::uuids::detail::md5::digest_type d;
  h.get_digest(d);
  const auto* bytes = reinterpret_cast<const unsigned char*>(&d);
  std::string out;
  char buf[3];
  // Boost stores the digest as four 32-bit words; the md5 byte order is each word's bytes from
  // the most significant (Boost < 1.86) — compare with the known sums below.
  for (int w = 0; w < 4; ++w) {
    for (int b = 3; b >= 0; --b) {
      std::snprintf(buf, sizeof(buf), "%02x", bytes[4 * w + b]);
      out += buf;
    }
  }
  return out;
}

TEST(LivoxCustomMsg, Md5SumsAreRosOwn) {
  // std_msgs/Header's md5 as ROS computes it from its own definition, a check of Md5() itself.
  EXPECT_EQ(Md5("uint32 seq\ntime stamp\nstring frame_id"), "2176decaecbce78abc3b96ef049fabed");
  EXPECT_EQ(Md5(kCustomPointMd5Text), kCustomPointMd5);
  EXPECT_EQ(Md5(kCustomMsgMd5Text), kCustomMsgMd5);
  EXPECT_STREQ(ros::message_traits::md5sum<CustomMsg>(), "e4d6829bdfe657cb6c21a746c86b21a6");
  EXPECT_STREQ(ros::message_traits::datatype<CustomMsg>(), "livox_ros_driver2/CustomMsg");
}

PointCloud SmallCloud() {
  PointCloud c;
  c.stamp_ns = 1'700'000'000'000'000'123LL;
  for (int i = 0; i < 7; ++i) {
    c.points.push_back(Vec3(1.0 + i, -0.5 * i, 0.25));
    c.times_ns.push_back(c.stamp_ns + 20'000LL * i + (i == 6 ? 99'000'001 : 0));
    c.ring.push_back(uint16_t(i % 4));
    c.intensity.push_back(float(40 * i));
  }
  return c;
}

std::vector<uint8_t> Serialize(const CustomMsg& m) {
  std::vector<uint8_t> bytes(ros::serialization::serializationLength(m));
  ros::serialization::OStream out(bytes.data(), uint32_t(bytes.size()));
  ros::serialization::serialize(out, m);
  return bytes;
}

TEST(LivoxCustomMsg, RoundTripAndTimes) {
  const CustomMsg m = FromPointCloud(SmallCloud(), "livox_frame");
  EXPECT_EQ(m.timebase, 1'700'000'000'000'000'123ULL);
  EXPECT_EQ(m.point_num, 7u);
  EXPECT_EQ(m.points[6].offset_time, 120'000u + 99'000'001u);
  EXPECT_EQ(m.points[6].reflectivity, 240);
  EXPECT_EQ(m.points[5].line, 1);
  const std::vector<uint8_t> bytes = Serialize(m);
  // Header (4 + 8 + 4 + 11 frame_id) + 8 + 4 + 1 + 3 + 4 + 7 × 19 packed points.
  EXPECT_EQ(bytes.size(), 27u + 20u + 7u * 19u);
  CheckCustomMsgWire(bytes.data(), bytes.size(), "test: ");
  CustomMsg back;
  ros::serialization::IStream in(const_cast<uint8_t*>(bytes.data()), uint32_t(bytes.size()));
  ros::serialization::deserialize(in, back);
  EXPECT_EQ(back.timebase, m.timebase);
  EXPECT_EQ(back.header.frame_id, "livox_frame");
  ASSERT_EQ(back.points.size(), 7u);
  EXPECT_EQ(back.points[6].offset_time, m.points[6].offset_time);
  EXPECT_EQ(back.points[3].x, 4.0f);
  const PointCloud c = ToPointCloud(back, "test: ");
  EXPECT_EQ(c.stamp_ns, SmallCloud().stamp_ns);
  EXPECT_EQ(c.times_ns, SmallCloud().times_ns);  // timebase + offset_time, to the ns
  EXPECT_EQ(c.ring, SmallCloud().ring);
  PointLayout layout;
  DecodePointCloud2(ToPointCloud2(back, ""), {}, "", &layout);
  EXPECT_EQ(layout.convention.driver, "Livox CustomPoint");
}

TEST(LivoxCustomMsg, CorruptOrTruncatedMessagesAreErrors) {
  const std::vector<uint8_t> bytes = Serialize(FromPointCloud(SmallCloud(), "livox_frame"));
  for (size_t cut : {size_t(5), size_t(30), bytes.size() - 1}) {
    ExpectError([&] { CheckCustomMsgWire(bytes.data(), cut, "bag.bag: message 3: "); },
                {"bag.bag: message 3: corrupt livox_ros_driver2/CustomMsg message"});
  }
  std::vector<uint8_t> huge = bytes;
  const size_t count_at = 27 + 16;  // the points' length
  huge[count_at + 3] = 0x7F;        // 2e9 points in a 180-byte message
  ExpectError([&] { CheckCustomMsgWire(huge.data(), huge.size(), ""); }, {"points need", "bytes"});
  std::vector<uint8_t> wrong_num = bytes;
  wrong_num[27 + 8] = 9;  // point_num 9, 7 points
  ExpectError([&] { CheckCustomMsgWire(wrong_num.data(), wrong_num.size(), ""); },
              {"point_num 9 but 7 points"});
  PointCloud late = SmallCloud();
  late.times_ns[2] = late.stamp_ns - 1;
  ExpectError([&] { FromPointCloud(late, "f"); }, {"point 2", "offset_time"});
}

TEST(LivoxCustomMsg, LidarTopicTypeChoice) {
  const std::map<std::string, std::string> livox_only = {{"/livox/lidar", kCustomMsgType},
                                                         {"/livox/imu", "sensor_msgs/Imu"}};
  EXPECT_TRUE(IsCustomMsgLidar(livox_only, ""));
  std::map<std::string, std::string> both = livox_only;
  both["/livox/points"] = "sensor_msgs/PointCloud2";
  EXPECT_FALSE(IsCustomMsgLidar(both, ""));  // PointCloud2 stays the default type
  EXPECT_TRUE(IsCustomMsgLidar(both, "/livox/lidar"));
  EXPECT_FALSE(IsCustomMsgLidar(both, "/livox/points"));
  EXPECT_FALSE(IsCustomMsgLidar({{"/velodyne_points", "sensor_msgs/PointCloud2"}}, ""));
}

}  // namespace
}  // namespace ctlio::io::livox
