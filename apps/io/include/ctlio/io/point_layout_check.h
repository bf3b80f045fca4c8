// The one check of a packed point layout, shared by every reader of point records
// (sensor_msgs/PointCloud2 messages, PCD and PLY files), so that the same defect gets the same
// answer in every layout. A layout is a list of fields (name, datatype, offset, count) inside a
// record of `point_step` bytes; a block is `height` rows of `row_step` bytes, each row holding
// `width` records. Everything is computed in 64 bits from 32-bit inputs, so nothing overflows, and
// the checks run before any allocation sized from the layout: a reader allocates only what the
// bytes it holds can fill.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/io/point_fields.h"

namespace ctlio::io {

// A point record of a lidar is tens of bytes; 1 MiB (PCD's limit too) leaves room for any driver
// while keeping a corrupt step from making one "point" span a whole message.
constexpr uint64_t kMaxPointRecordBytes = uint64_t{1} << 20;
// Elements of one field (PCD COUNT): a few for descriptors, never more than 65536.
constexpr uint64_t kMaxFieldElements = uint64_t{1} << 16;

// Field geometry. Errors (std::runtime_error, prefixed by `where`, listing the fields found):
// point_step 0 or above kMaxPointRecordBytes, a field of an unknown datatype, a count above
// kMaxFieldElements, a field whose bytes (offset + size × count) end past point_step.
void CheckPointFields(const std::vector<PointField>& fields, uint64_t point_step,
                      const std::string& where);

struct PointBlock {
  uint64_t width = 0;       // records per row
  uint64_t height = 1;      // rows
  uint64_t point_step = 0;  // bytes per record
  uint64_t row_step = 0;    // bytes per row (≥ width × point_step; more is row padding)
  uint64_t points() const { return width * height; }
};
// A PCD/PLY body: `n` records of `point_step` bytes, one row.
PointBlock PackedBlock(uint64_t n, uint64_t point_step);

// Byte counts. Errors (prefixed by `where`; `what` names the data, e.g. "data", "binary data"):
// records of 0 B or above kMaxPointRecordBytes when there are points, a row_step shorter than
// width × point_step, and `data_bytes` ≠ height × row_step (short data, data longer than declared,
// a huge width over a few bytes). The message gives both sizes.
void CheckPointBytes(const PointBlock& block, uint64_t data_bytes, const std::string& where,
                     const std::string& what = "data");

}  // namespace ctlio::io
