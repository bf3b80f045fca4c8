#include "ctlio/io/pointcloud2.h"

#include <stdexcept>

#include "ctlio/io/point_layout_check.h"

namespace ctlio::io {

std::vector<PointField> FieldsOf(const sensor_msgs::PointCloud2& msg) {
  std::vector<PointField> fields;
  fields.reserve(msg.fields.size());
  for (const auto& f : msg.fields) fields.push_back({f.name, f.datatype, f.offset, f.count});
  return fields;
}

PointCloud DecodePointCloud2(const sensor_msgs::PointCloud2& msg, const TimeFieldOptions& options,
                             const std::string& where, PointLayout* layout_out) {
  if (msg.is_bigendian) throw std::runtime_error(where + "big-endian point data is not supported");
  // Sizes first (point_layout_check.h): nothing below reads or reserves more than `data` holds.
  PointBlock block;
  block.width = msg.width;
  block.height = msg.height;
  block.point_step = msg.point_step;
  block.row_step = msg.row_step;
  CheckPointBytes(block, msg.data.size(), where);
  const PointLayout layout = DetectPointLayout(FieldsOf(msg), msg.point_step, options, where);
  PointCloud cloud;
  cloud.stamp_ns = int64_t(msg.header.stamp.toNSec());
  // (A zero width over 4e9 empty rows would otherwise spin through them.)
  for (uint32_t r = 0; msg.width > 0 && r < msg.height; ++r) {
    DecodePoints(msg.data.data() + size_t(r) * msg.row_step, msg.width, layout, cloud.stamp_ns,
                 where, &cloud);
  }
  if (layout_out) *layout_out = layout;
  return cloud;
}

sensor_msgs::PointCloud2 EncodePointCloud2(const PointCloud& cloud,
                                           const std::vector<PointField>& fields,
                                           uint32_t point_step, const TimeConvention& convention,
                                           const std::string& frame_id) {
  sensor_msgs::PointCloud2 msg;
  msg.header.stamp.fromNSec(uint64_t(cloud.stamp_ns));
  msg.header.frame_id = frame_id;
  for (const PointField& f : fields) {
    sensor_msgs::PointField m;
    m.name = f.name;
    m.offset = f.offset;
    m.datatype = f.datatype;
    m.count = f.count;
    msg.fields.push_back(m);
  }
  msg.height = 1;
  msg.width = uint32_t(cloud.size());
  msg.point_step = point_step;
  msg.row_step = point_step * msg.width;
  msg.is_bigendian = false;
  msg.is_dense = true;
  msg.data = EncodePoints(cloud, fields, point_step, convention);
  return msg;
}

}  // namespace ctlio::io
