// sensor_msgs/PointCloud2 ↔ PointCloud through the field detection of point_fields.h (the same
// detection as PCD files).
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <string>
#include <vector>

#include "ctlio/io/point_fields.h"

namespace ctlio::io {

std::vector<PointField> FieldsOf(const sensor_msgs::PointCloud2& msg);

// Decodes a message: cloud.stamp_ns = the header stamp, times absolute. Errors (std::runtime_error
// prefixed by `where`): big-endian data, every byte-count and field-geometry error of
// point_layout_check.h (data ≠ height × row_step, row_step < width × point_step, point_step 0, a
// field past point_step; checked before anything is reserved), and every layout error of
// DetectPointLayout (missing x/y/z, wrong field types, a time-like field of the wrong type; the
// fields found are listed). Without a
// time field the times are left empty (the caller applies FillTimesFromAzimuth). `layout` (if not
// null) receives the detected layout.
PointCloud DecodePointCloud2(const sensor_msgs::PointCloud2& msg, const TimeFieldOptions& options,
                             const std::string& where, PointLayout* layout = nullptr);

// Encodes `cloud` with the given layout; the header stamp is cloud.stamp_ns.
sensor_msgs::PointCloud2 EncodePointCloud2(const PointCloud& cloud,
                                           const std::vector<PointField>& fields,
                                           uint32_t point_step, const TimeConvention& convention,
                                           const std::string& frame_id);

}  // namespace ctlio::io
