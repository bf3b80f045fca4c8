#include "ctlio/io/ros_wire_check.h"

#include <cstring>

namespace ctlio::io {
namespace {

// A bounded cursor over a serialised message (ROS 1: little-endian, uint32 lengths before strings
// and arrays, no padding).
class Wire {
 public:
  Wire(const uint8_t* data, size_t size, std::string prefix)
      : data_(data), size_(size), prefix_(std::move(prefix)) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(prefix_ + what + " (at byte " + std::to_string(pos_) + " of " +
                             std::to_string(size_) + ")");
  }
  void Skip(size_t n, const char* what) {
    if (n > size_ - pos_) {
      Fail(std::string(what) + " needs " + std::to_string(n) + " B, " +
           std::to_string(size_ - pos_) + " B left");
    }
    pos_ += n;
  }
  uint32_t U32(const char* what) {
    const size_t at = pos_;
    Skip(4, what);
    uint32_t v;
    std::memcpy(&v, data_ + at, 4);
    return v;
  }
  void String(const char* what) { Skip(U32(what), what); }
  // An array length, bounded by what its smallest element leaves room for.
  uint32_t Count(size_t min_element_bytes, const char* what) {
    const uint32_t n = U32(what);
    if (static_cast<uint64_t>(n) * min_element_bytes > size_ - pos_) {
      Fail(std::string(what) + " count " + std::to_string(n) + " needs at least " +
           std::to_string(static_cast<uint64_t>(n) * min_element_bytes) + " B, " +
           std::to_string(size_ - pos_) + " B left");
    }
    return n;
  }
  void Header() {
    Skip(4 + 8, "header seq and stamp");
    String("header frame_id");
  }
  void End() const {
    if (pos_ != size_) {
      Fail(std::to_string(size_ - pos_) + " B after the message's last field");
    }
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string prefix_;
};

}  // namespace

void CheckPointCloud2Wire(const uint8_t* data, size_t size, const std::string& where) {
  Wire w(data, size, where + "corrupt sensor_msgs/PointCloud2 message: ");
  w.Header();
  w.Skip(8, "height and width");
  // PointField: name (≥ 4 B), offset uint32, datatype uint8, count uint32.
  const uint32_t fields = w.Count(4 + 4 + 1 + 4, "fields");
  for (uint32_t i = 0; i < fields; ++i) {
    w.String("field name");
    w.Skip(4 + 1 + 4, "field offset, datatype and count");
  }
  w.Skip(1 + 4 + 4, "is_bigendian, point_step and row_step");
  w.Skip(w.Count(1, "data"), "data");
  w.Skip(1, "is_dense");
  w.End();
}

void CheckTfMessageWire(const uint8_t* data, size_t size, const std::string& where) {
  Wire w(data, size, where + "corrupt tf2_msgs/TFMessage message: ");
  // TransformStamped: header (≥ 16 B), child_frame_id (≥ 4 B), translation and rotation (7
  // float64).
  const uint32_t n = w.Count(16 + 4 + 56, "transforms");
  for (uint32_t i = 0; i < n; ++i) {
    w.Header();
    w.String("child_frame_id");
    w.Skip(56, "transform");
  }
  w.End();
}

}  // namespace ctlio::io
