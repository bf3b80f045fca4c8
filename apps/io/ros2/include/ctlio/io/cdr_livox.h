// Livox's own point-cloud message in ROS 2 bags, `livox_ros_driver2/msg/CustomMsg` (the driver's
// xfer_format 1), in CDR (cdr.h). No ROS package defines it in Debian, so the struct is ours, field
// for field as the driver's message definitions:
//   CustomMsg: std_msgs/Header header, uint64 timebase (ns, the first point's time),
//     uint32 point_num, uint8 lidar_id, uint8[3] rsvd, CustomPoint[] points
//   CustomPoint: uint32 offset_time (ns since timebase), float32 x, y, z, uint8 reflectivity,
//     uint8 tag, uint8 line
// Errors as cdr_messages.h's: "<where>corrupt livox_ros_driver2/msg/CustomMsg message: <what>".
#pragma once

#include <std_msgs/Header.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/io/cdr.h"

namespace ctlio::io::ros2 {

struct LivoxCustomPoint {
  uint32_t offset_time = 0;
  float x = 0, y = 0, z = 0;
  uint8_t reflectivity = 0, tag = 0, line = 0;
  bool operator==(const LivoxCustomPoint& o) const {
    return offset_time == o.offset_time && x == o.x && y == o.y && z == o.z &&
           reflectivity == o.reflectivity && tag == o.tag && line == o.line;
  }
};

struct LivoxCustomMsg {
  std_msgs::Header header;
  uint64_t timebase = 0;
  uint32_t point_num = 0;  // as sent; points.size() is what the message holds
  uint8_t lidar_id = 0;
  std::array<uint8_t, 3> rsvd{};
  std::vector<LivoxCustomPoint> points;
  bool operator==(const LivoxCustomMsg& o) const {
    return header == o.header && timebase == o.timebase && point_num == o.point_num &&
           lidar_id == o.lidar_id && rsvd == o.rsvd && points == o.points;
  }
};

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, LivoxCustomMsg* msg);
std::vector<uint8_t> EncodeCdr(const LivoxCustomMsg& msg, CdrEndian endian = CdrEndian::kLittle);

}  // namespace ctlio::io::ros2
