// livox_ros_driver2's own point-cloud message (the driver's xfer_format 1; the input of FAST-LIO
// and most Livox pipelines), field for field as the driver's message definitions. No Debian
// package defines it, so the struct is ctlio's, one for both bag kinds: ROS 1 serialization in
// livox_custom_msg.h, ROS 2 CDR in cdr_livox.h.
//   CustomMsg:   std_msgs/Header header; uint64 timebase (ns, the first point's time);
//                uint32 point_num; uint8 lidar_id; uint8[3] rsvd; CustomPoint[] points
//   CustomPoint: uint32 offset_time (ns after timebase); float32 x, y, z; uint8 reflectivity;
//                uint8 tag; uint8 line
#pragma once

#include <std_msgs/Header.h>

#include <boost/array.hpp>
#include <cstdint>
#include <vector>

namespace ctlio::io::livox {

struct CustomPoint {
  uint32_t offset_time = 0;  // ns after timebase
  float x = 0, y = 0, z = 0;
  uint8_t reflectivity = 0;
  uint8_t tag = 0;
  uint8_t line = 0;
  bool operator==(const CustomPoint& o) const {
    return offset_time == o.offset_time && x == o.x && y == o.y && z == o.z &&
           reflectivity == o.reflectivity && tag == o.tag && line == o.line;
  }
};

struct CustomMsg {
  std_msgs::Header header;
  uint64_t timebase = 0;   // ns, the first point's time
  uint32_t point_num = 0;  // as sent; points.size() is what the message holds
  uint8_t lidar_id = 0;
  boost::array<uint8_t, 3> rsvd{{0, 0, 0}};  // boost::array: ROS 1's serializer has it
  std::vector<CustomPoint> points;
  bool operator==(const CustomMsg& o) const {
    return header == o.header && timebase == o.timebase && point_num == o.point_num &&
           lidar_id == o.lidar_id && rsvd == o.rsvd && points == o.points;
  }
};

}  // namespace ctlio::io::livox
