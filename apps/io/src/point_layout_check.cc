#include "ctlio/io/point_layout_check.h"

#include <stdexcept>

namespace ctlio::io {

void CheckPointFields(const std::vector<PointField>& fields, uint64_t point_step,
                      const std::string& where) {
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(where + what + " (fields found: " + DescribeFields(fields) + ")");
  };
  if (point_step == 0) {
    fail("point_step is 0");
  }
  if (point_step > kMaxPointRecordBytes) {
    fail("point_step " + std::to_string(point_step) + " B exceeds " +
         std::to_string(kMaxPointRecordBytes) + " B");
  }
  for (const PointField& f : fields) {
    const uint64_t size = FieldDatatypeSize(f.datatype);
    if (size == 0) {
      fail("field '" + f.name + "' has an unknown datatype");
    }
    if (f.count > kMaxFieldElements) {
      fail("field '" + f.name + "' has count " + std::to_string(f.count) + " (at most " +
           std::to_string(kMaxFieldElements) + ")");
    }
    // 32-bit offset + 8 × 2^16 fits 64 bits: no overflow.
    const uint64_t end = static_cast<uint64_t>(f.offset) + size * f.count;
    if (end > point_step) {
      fail("field '" + f.name + "' ends past the point step of " + std::to_string(point_step) +
           " B (" + std::to_string(f.count) + " × " + FieldDatatypeName(f.datatype) + " at byte " +
           std::to_string(f.offset) + " end at byte " + std::to_string(end) + ")");
    }
  }
}

PointBlock PackedBlock(uint64_t n, uint64_t point_step) {
  PointBlock b;
  b.width = n;
  b.height = 1;
  b.point_step = point_step;
  b.row_step = n * point_step;  // callers bound n < 2^31 and point_step ≤ 1 MiB: no overflow
  return b;
}

void CheckPointBytes(const PointBlock& b, uint64_t data_bytes, const std::string& where,
                     const std::string& what) {
  auto fail = [&](const std::string& why) { throw std::runtime_error(where + why); };
  // Counts and the step are 32-bit in every format (PointCloud2 fields; PCD and PLY are bounded
  // below 2^31 points and 1 MiB records), so the products below fit 64 bits; row_step of a packed
  // file block is their product, hence not bounded here but in the multiplication.
  const uint64_t kMax32 = 0xFFFFFFFFull;
  if (b.width > kMax32 || b.height > kMax32 || b.point_step > kMax32) {
    fail("width, height or point_step exceeds 32 bits");
  }
  const uint64_t points = b.width * b.height;  // < 2^64
  if (points > 0 && b.point_step == 0) {
    fail("point_step is 0 for " + std::to_string(points) + " points");
  }
  if (points > 0 && b.point_step > kMaxPointRecordBytes) {
    fail("point_step " + std::to_string(b.point_step) + " B exceeds " +
         std::to_string(kMaxPointRecordBytes) + " B");
  }
  const uint64_t row_bytes = b.width * b.point_step;  // both < 2^32: no overflow
  if (b.height > 0 && b.row_step < row_bytes) {
    fail("row_step " + std::to_string(b.row_step) + " B is shorter than a row of " +
         std::to_string(b.width) + " points × " + std::to_string(b.point_step) +
         " B = " + std::to_string(row_bytes) + " B");
  }
  uint64_t needed = 0;
  if (__builtin_mul_overflow(b.height, b.row_step, &needed)) {
    fail(std::to_string(b.height) + " rows of " + std::to_string(b.row_step) + " B exceed 64 bits");
  }
  if (data_bytes != needed) {
    std::string shape = std::to_string(b.height) + " × " + std::to_string(b.width) + " points of " +
                        std::to_string(b.point_step) + " B";
    if (b.row_step != row_bytes) {
      shape += " in rows of " + std::to_string(b.row_step) + " B";
    }
    fail(what + " holds " + std::to_string(data_bytes) + " B; " + shape + " need " +
         std::to_string(needed) + " B");
  }
}

}  // namespace ctlio::io
