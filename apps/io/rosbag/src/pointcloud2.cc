#include "ctlio/io/pointcloud2.h"

#include <stdexcept>

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
  const PointLayout layout = DetectPointLayout(FieldsOf(msg), msg.point_step, options, where);
  const size_t row_bytes = size_t(msg.width) * msg.point_step;
  if (msg.height > 0 && msg.width > 0 &&
      (msg.row_step < row_bytes ||
       msg.data.size() < size_t(msg.height - 1) * msg.row_step + row_bytes)) {
    throw std::runtime_error(where + "data holds " + std::to_string(msg.data.size()) + " B for " +
                             std::to_string(msg.height) + " × " + std::to_string(msg.width) +
                             " points of " + std::to_string(msg.point_step) + " B (row_step " +
                             std::to_string(msg.row_step) + ")");
  }
  PointCloud cloud;
  cloud.stamp_ns = int64_t(msg.header.stamp.toNSec());
  for (uint32_t r = 0; r < msg.height; ++r) {
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
