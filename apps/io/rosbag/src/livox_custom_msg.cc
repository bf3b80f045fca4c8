#include "ctlio/io/livox_custom_msg.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/driver_conventions.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/ros_wire_check.h"

namespace ctlio::io::livox {

const char kCustomPointMd5Text[] =
    "uint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\nuint8 reflectivity\nuint8 tag\n"
    "uint8 line";
const char kCustomMsgMd5Text[] =
    "2176decaecbce78abc3b96ef049fabed header\nuint64 timebase\nuint32 point_num\nuint8 "
    "lidar_id\nuint8[3] rsvd\n109a3cc548bb1f96626be89a5008bd6d points";
const char kCustomPointMd5[] = "109a3cc548bb1f96626be89a5008bd6d";
const char kCustomMsgMd5[] = "e4d6829bdfe657cb6c21a746c86b21a6";
const char kCustomMsgDefinition[] =
    "# Livox publish pointcloud msg format.\n"
    "\n"
    "Header header             # ROS standard message header\n"
    "uint64 timebase           # The time of first point\n"
    "uint32 point_num          # Total number of pointclouds\n"
    "uint8  lidar_id           # Lidar device id number\n"
    "uint8[3]  rsvd            # Reserved use\n"
    "CustomPoint[] points      # Pointcloud data\n"
    "\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\n"
    "uint32 seq\n"
    "time stamp\n"
    "string frame_id\n"
    "\n"
    "================================================================================\n"
    "MSG: livox_ros_driver2/CustomPoint\n"
    "# Livox costom pointcloud format.\n"
    "\n"
    "uint32 offset_time      # offset time relative to the base time\n"
    "float32 x               # X axis, unit:m\n"
    "float32 y               # Y axis, unit:m\n"
    "float32 z               # Z axis, unit:m\n"
    "uint8 reflectivity      # reflectivity, 0~255\n"
    "uint8 tag               # livox tag\n"
    "uint8 line              # laser number in lidar\n";

namespace {

constexpr size_t kPointBytes = 19;  // uint32 + 3 float32 + 3 uint8, packed on the wire

uint32_t ReadU32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;  // ROS 1 wire format is little-endian, as the supported hosts
}

}  // namespace

void CheckCustomMsgWire(const uint8_t* data, size_t size, const std::string& where) {
  const std::string prefix = where + "corrupt livox_ros_driver2/CustomMsg message: ";
  size_t at = 0;
  auto need = [&](size_t n, const char* what) {
    if (n > size - at) {
      throw std::runtime_error(prefix + what + " needs " + std::to_string(n) + " bytes, " +
                               std::to_string(size - at) + " left of " + std::to_string(size));
    }
  };
  need(12, "header seq and stamp");
  at += 12;
  need(4, "frame_id length");
  const uint32_t frame_len = ReadU32(data + at);
  at += 4;
  need(frame_len, "frame_id");
  at += frame_len;
  need(8 + 4 + 1 + 3, "timebase, point_num, lidar_id and rsvd");
  const uint32_t point_num = ReadU32(data + at + 8);
  at += 16;
  need(4, "points length");
  const uint32_t count = ReadU32(data + at);
  at += 4;
  if (uint64_t(count) * kPointBytes != uint64_t(size - at)) {
    throw std::runtime_error(prefix + std::to_string(count) + " points need " +
                             std::to_string(uint64_t(count) * kPointBytes) + " bytes, " +
                             std::to_string(size - at) + " left");
  }
  if (point_num != count) {
    throw std::runtime_error(prefix + "point_num " + std::to_string(point_num) + " but " +
                             std::to_string(count) + " points");
  }
}

sensor_msgs::PointCloud2 ToPointCloud2(const CustomMsg& msg, const std::string& where) {
  if (msg.timebase < 1 || msg.timebase / 1'000'000'000ULL > 0xFFFFFFFFULL) {
    throw std::runtime_error(where + "CustomMsg timebase " + std::to_string(msg.timebase) +
                             " ns is not a ROS time");
  }
  sensor_msgs::PointCloud2 out;
  out.header = msg.header;
  out.header.stamp.fromNSec(msg.timebase);
  uint32_t point_step = 0;
  for (const PointField& f : DriverFields(PointFormat::kLivoxCustomMsg, &point_step)) {
    sensor_msgs::PointField m;
    m.name = f.name;
    m.offset = f.offset;
    m.datatype = f.datatype;
    m.count = f.count;
    out.fields.push_back(m);
  }
  out.height = 1;
  out.width = uint32_t(msg.points.size());
  out.point_step = point_step;
  out.row_step = point_step * out.width;
  out.is_bigendian = false;
  out.is_dense = true;
  out.data.resize(size_t(out.row_step));
  uint8_t* p = out.data.data();
  for (const CustomPoint& q : msg.points) {
    std::memcpy(p, &q.offset_time, 4);
    std::memcpy(p + 4, &q.x, 4);
    std::memcpy(p + 8, &q.y, 4);
    std::memcpy(p + 12, &q.z, 4);
    p[16] = q.reflectivity;
    p[17] = q.tag;
    p[18] = q.line;
    p += point_step;
  }
  return out;
}

PointCloud ToPointCloud(const CustomMsg& msg, const std::string& where) {
  PointCloud cloud = DecodePointCloud2(ToPointCloud2(msg, where), {}, where);
  cloud.ring.resize(cloud.size());
  size_t i = 0;  // DecodePoints drops non-finite points: keep the lines of the kept ones
  for (const CustomPoint& q : msg.points) {
    if (std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && i < cloud.size()) {
      cloud.ring[i++] = q.line;
    }
  }
  return cloud;
}

CustomMsg FromPointCloud(const PointCloud& cloud, const std::string& frame_id) {
  if (cloud.stamp_ns < 1) {
    throw std::runtime_error("CustomMsg: scan start " + std::to_string(cloud.stamp_ns) +
                             " ns is not a ROS time");
  }
  CustomMsg msg;
  msg.timebase = uint64_t(cloud.stamp_ns);
  msg.header.stamp.fromNSec(msg.timebase);
  msg.header.frame_id = frame_id;
  msg.points.resize(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    CustomPoint& q = msg.points[i];
    const int64_t dt = cloud.has_times() ? cloud.times_ns[i] - cloud.stamp_ns : 0;
    if (dt < 0 || dt > int64_t(0xFFFFFFFFLL)) {
      throw std::runtime_error("CustomMsg: point " + std::to_string(i) + " at " +
                               std::to_string(dt) + " ns from the scan start does not fit " +
                               "offset_time (uint32 ns)");
    }
    q.offset_time = uint32_t(dt);
    q.x = float(cloud.points[i].x());
    q.y = float(cloud.points[i].y());
    q.z = float(cloud.points[i].z());
    if (cloud.intensity.size() == cloud.size()) {
      q.reflectivity = uint8_t(std::clamp(std::lround(cloud.intensity[i]), 0L, 255L));
    }
    if (cloud.ring.size() == cloud.size()) q.line = uint8_t(cloud.ring[i]);
  }
  msg.point_num = uint32_t(msg.points.size());
  return msg;
}

bool IsCustomMsgLidar(const std::map<std::string, std::string>& topic_types,
                      const std::string& given) {
  const std::string custom = ros::message_traits::datatype<CustomMsg>();
  if (!given.empty()) {
    const auto it = topic_types.find(given);
    return it != topic_types.end() && it->second == custom;
  }
  bool any_custom = false;
  for (const auto& [topic, type] : topic_types) {
    if (type == "sensor_msgs/PointCloud2") return false;
    any_custom = any_custom || type == custom;
  }
  return any_custom;
}

sensor_msgs::PointCloud2 ReadLidarMessage(BagStream& stream, bool custom_msg,
                                          const std::string& where) {
  if (!custom_msg) {
    sensor_msgs::PointCloud2 m;
    stream.Read(where, &m);
    return m;
  }
  CustomMsg m;
  stream.Read(where, &m);
  return ToPointCloud2(m, where);
}

}  // namespace ctlio::io::livox
