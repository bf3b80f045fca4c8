// livox_ros_driver2/msg/CustomMsg in CDR (cdr_livox.h): a hand-built little-endian message checked
// field by field (the two pad bytes before the uint64 timebase), the encoder against the same
// bytes, a big-endian round trip, and every truncation an error.
#include "ctlio/io/cdr_livox.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace ctlio::io::ros2 {
namespace {

using Bytes = std::vector<uint8_t>;

// stamp 3 s 4 ns, frame "a", timebase 2^40 + 5 ns, point_num 1, lidar_id 9, rsvd 1 2 3, one point:
// offset_time 1000 ns, x 1.0f, y -2.0f, z 0.5f, reflectivity 200, tag 16, line 3.
// clang-format off
const Bytes kCustomLe = {
    0x00, 0x01, 0x00, 0x00,                     // encapsulation CDR_LE
    3, 0, 0, 0,  4, 0, 0, 0,                    // stamp
    2, 0, 0, 0,  'a', 0,  /*pad*/ 0, 0,         // frame_id
    5, 0, 0, 0, 0, 1, 0, 0,                     // timebase
    1, 0, 0, 0,                                 // point_num
    9,  1, 2, 3,                                // lidar_id, rsvd
    1, 0, 0, 0,                                 // points: 1
    0xE8, 0x03, 0, 0,                           // offset_time 1000
    0, 0, 0x80, 0x3F,  0, 0, 0, 0xC0,  0, 0, 0, 0x3F,  // x, y, z
    200, 16, 3,                                 // reflectivity, tag, line
};
// clang-format on

TEST(CdrLivox, DecodesAHandBuiltCustomMsgFieldByField) {
  livox::CustomMsg m;
  DecodeCdr(kCustomLe.data(), kCustomLe.size(), "", &m);
  EXPECT_EQ(m.header.stamp.sec, 3u);
  EXPECT_EQ(m.header.stamp.nsec, 4u);
  EXPECT_EQ(m.header.frame_id, "a");
  EXPECT_EQ(m.timebase, (uint64_t(1) << 40) + 5);
  EXPECT_EQ(m.point_num, 1u);
  EXPECT_EQ(m.lidar_id, 9);
  EXPECT_EQ(m.rsvd, (boost::array<uint8_t, 3>{{1, 2, 3}}));
  ASSERT_EQ(m.points.size(), 1u);
  EXPECT_EQ(m.points[0].offset_time, 1000u);
  EXPECT_EQ(m.points[0].x, 1.0f);
  EXPECT_EQ(m.points[0].y, -2.0f);
  EXPECT_EQ(m.points[0].z, 0.5f);
  EXPECT_EQ(m.points[0].reflectivity, 200);
  EXPECT_EQ(m.points[0].tag, 16);
  EXPECT_EQ(m.points[0].line, 3);
  EXPECT_EQ(EncodeCdr(m), kCustomLe);
  // Big-endian: other bytes, the same message.
  const Bytes be = EncodeCdr(m, CdrEndian::kBig);
  EXPECT_NE(be, kCustomLe);
  livox::CustomMsg again;
  DecodeCdr(be.data(), be.size(), "", &again);
  EXPECT_EQ(again, m);
}

TEST(CdrLivox, EveryTruncationAndAnImpossiblePointCountAreErrors) {
  for (size_t n = 0; n < kCustomLe.size(); ++n) {
    livox::CustomMsg m;
    try {
      DecodeCdr(kCustomLe.data(), n, "bag: topic /livox/lidar, message 2: ", &m);
      ADD_FAILURE() << "cut at " << n << " decoded";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(
                    "bag: topic /livox/lidar, message 2: corrupt livox_ros_driver2/msg/CustomMsg "
                    "message: "),
                std::string::npos)
          << e.what();
    }
  }
  Bytes b = kCustomLe;
  b[36] = 2;  // 2 points of ≥ 19 bytes in 19 bytes
  livox::CustomMsg m;
  try {
    DecodeCdr(b.data(), b.size(), "", &m);
    ADD_FAILURE() << "decoded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "points: 2 elements of at least 19 bytes, 19 bytes left (at byte 40)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace ctlio::io::ros2
