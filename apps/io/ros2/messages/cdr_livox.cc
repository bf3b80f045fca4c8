#include "ctlio/io/cdr_livox.h"

#include <stdexcept>

#include "ctlio/io/cdr_messages.h"

namespace ctlio::io::ros2 {
namespace {

// offset_time, x, y, z, reflectivity, tag, line: the least a CustomPoint takes (padding adds).
constexpr size_t kMinPointBytes = 4 + 3 * 4 + 3;

}  // namespace

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, livox::CustomMsg* msg) {
  CdrReader in(data, size, where, "livox_ros_driver2/msg/CustomMsg");
  ReadHeader(in, &msg->header);
  msg->timebase = in.U64("timebase");
  msg->point_num = in.U32("point_num");
  msg->lidar_id = in.U8("lidar_id");
  for (uint8_t& r : msg->rsvd) r = in.U8("rsvd");
  const uint32_t n = in.Count("points", kMinPointBytes);
  msg->points.clear();
  msg->points.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    livox::CustomPoint p;
    p.offset_time = in.U32("points.offset_time");
    p.x = in.F32("points.x");
    p.y = in.F32("points.y");
    p.z = in.F32("points.z");
    p.reflectivity = in.U8("points.reflectivity");
    p.tag = in.U8("points.tag");
    p.line = in.U8("points.line");
    msg->points.push_back(p);
  }
  in.Finish();
}

std::vector<uint8_t> EncodeCdr(const livox::CustomMsg& msg, CdrEndian endian) {
  if (msg.points.size() > UINT32_MAX) throw std::runtime_error("CustomMsg: too many points");
  CdrWriter out(endian);
  WriteHeader(out, msg.header);
  out.U64(msg.timebase);
  out.U32(msg.point_num);
  out.U8(msg.lidar_id);
  for (uint8_t r : msg.rsvd) out.U8(r);
  out.U32(uint32_t(msg.points.size()));
  for (const livox::CustomPoint& p : msg.points) {
    out.U32(p.offset_time);
    out.F32(p.x);
    out.F32(p.y);
    out.F32(p.z);
    out.U8(p.reflectivity);
    out.U8(p.tag);
    out.U8(p.line);
  }
  return out.Take();
}

}  // namespace ctlio::io::ros2
