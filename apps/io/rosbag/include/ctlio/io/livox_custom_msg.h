// livox_ros_driver2/CustomMsg (the Livox ROS driver's own cloud, xfer_format 1, the input of
// FAST-LIO and most Livox pipelines) for ROS 1 bags, written here from the message definition so
// that no Livox package is needed:
//
//   CustomMsg:   std_msgs/Header header; uint64 timebase; uint32 point_num; uint8 lidar_id;
//                uint8[3] rsvd; CustomPoint[] points
//   CustomPoint: uint32 offset_time; float32 x y z; uint8 reflectivity; uint8 tag; uint8 line
//
// Times: `timebase` is the absolute time [ns] of the message's first point ("the time of first
// point" in the driver's definition) and each point's `offset_time` is ns after it, so a point's
// time is timebase + offset_time. The scan start is `timebase`; the header stamp is not used for
// point times (driver 2 stamps it with timebase too, but recorders may restamp it on arrival).
//
// ROS 1 identity: datatype "livox_ros_driver2/CustomMsg", md5sum e4d6829bdfe657cb6c21a746c86b21a6,
// computed as ROS does (md5 of the definition's fields with each nested type replaced by its own
// md5: std_msgs/Header 2176decaecbce78abc3b96ef049fabed, CustomPoint
// 109a3cc548bb1f96626be89a5008bd6d; livox_custom_msg_test recomputes both), so bags written here
// play to the driver's subscribers and the driver's bags read here.
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <boost/array.hpp>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "ctlio/io/livox_msgs.h"
#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {
class BagStream;  // bag_stream.h
}  // namespace ctlio::io

namespace ctlio::io::livox {

// The md5 texts (one field per line, nested types as their md5sums) and sums.
extern const char kCustomPointMd5Text[];
extern const char kCustomMsgMd5Text[];
extern const char kCustomPointMd5[];
extern const char kCustomMsgMd5[];
extern const char kCustomMsgDefinition[];  // the full text a bag's connection record carries
inline constexpr char kCustomMsgType[] = "livox_ros_driver2/CustomMsg";

// Bounds every length of the serialized message by its `size` bytes (as CheckPointCloud2Wire,
// ros_wire_check.h: the library would resize `points` to a corrupt count first) and requires
// point_num to equal the number of points; throws std::runtime_error "<where>corrupt
// livox_ros_driver2/CustomMsg message: ...".
void CheckCustomMsgWire(const uint8_t* data, size_t size, const std::string& where);

// The message as a PointCloud2 with the CustomPoint layout (x y z float32, intensity =
// reflectivity, tag, line uint8, offset_time uint32) stamped at timebase, so the per-point time
// detection of point_fields.h reads offset_time as ns after the scan start. Throws if timebase
// does not fit a ros::Time.
sensor_msgs::PointCloud2 ToPointCloud2(const CustomMsg& msg, const std::string& where);
// The points with absolute times timebase + offset_time, ring = line, intensity = reflectivity.
PointCloud ToPointCloud(const CustomMsg& msg, const std::string& where);
// A scan as the driver would publish it: timebase = cloud.stamp_ns (the scan start), offset_time
// = time − timebase (throws if a time is before it or 4.29 s after), line = ring, reflectivity =
// intensity clamped to [0, 255], header stamped at timebase.
CustomMsg FromPointCloud(const PointCloud& cloud, const std::string& frame_id);

// Bag reading (RosbagSource). The lidar topic is a CustomMsg one when `given` names one, or when
// nothing is given and the bag has CustomMsg topics but no PointCloud2 topic.
bool IsCustomMsgLidar(const std::map<std::string, std::string>& topic_types,
                      const std::string& given);
// The current message of `stream` (ROS 1 or ROS 2, bag_stream.h) as a PointCloud2: read and
// checked as a PointCloud2, or as a CustomMsg converted by ToPointCloud2.
sensor_msgs::PointCloud2 ReadLidarMessage(BagStream& stream, bool custom_msg,
                                          const std::string& where);

}  // namespace ctlio::io::livox

namespace ros {
namespace message_traits {

template <>
struct IsMessage<ctlio::io::livox::CustomMsg> : TrueType {};
template <>
struct HasHeader<ctlio::io::livox::CustomMsg> : TrueType {};
template <>
struct MD5Sum<ctlio::io::livox::CustomMsg> {
  static const char* value() { return ctlio::io::livox::kCustomMsgMd5; }
  static const char* value(const ctlio::io::livox::CustomMsg&) { return value(); }
};
template <>
struct DataType<ctlio::io::livox::CustomMsg> {
  static const char* value() { return ctlio::io::livox::kCustomMsgType; }
  static const char* value(const ctlio::io::livox::CustomMsg&) { return value(); }
};
template <>
struct Definition<ctlio::io::livox::CustomMsg> {
  static const char* value() { return ctlio::io::livox::kCustomMsgDefinition; }
  static const char* value(const ctlio::io::livox::CustomMsg&) { return value(); }
};

}  // namespace message_traits

namespace serialization {

template <>
struct Serializer<ctlio::io::livox::CustomPoint> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T m) {
    stream.next(m.offset_time);
    stream.next(m.x);
    stream.next(m.y);
    stream.next(m.z);
    stream.next(m.reflectivity);
    stream.next(m.tag);
    stream.next(m.line);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};

template <>
struct Serializer<ctlio::io::livox::CustomMsg> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T m) {
    stream.next(m.header);
    stream.next(m.timebase);
    stream.next(m.point_num);
    stream.next(m.lidar_id);
    stream.next(m.rsvd);
    stream.next(m.points);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};

}  // namespace serialization
}  // namespace ros
