// CDR serialization as ROS 2 bags hold it (OMG DDS-XTypes 1.3 §7.4.3.4 "XCDR1", the `cdr` format
// of rosbag2): a 4-byte encapsulation header — bytes 0x00 0x01 for CDR_LE, 0x00 0x00 for CDR_BE,
// then two option bytes — followed by the body. In the body each primitive of n bytes is aligned
// to n (at most 8) relative to the body's start; a string is a uint32 length counting its
// terminating NUL, then the bytes; a sequence a uint32 element count, then the elements; a fixed
// array its elements only.
//
// CdrReader bounds every length and count by the bytes left before anything is allocated; each
// error is std::runtime_error "<where>corrupt <type> message: <what> (at byte N)".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ctlio::io::ros2 {

class CdrReader {
 public:
  // `data` holds the encapsulation header and the body; `where` (bag, topic, message) and `type`
  // ("sensor_msgs/msg/Imu") name the message in errors.
  CdrReader(const uint8_t* data, size_t size, const std::string& where, const std::string& type);

  uint8_t U8(const char* what);
  bool Bool(const char* what);  // 0 or 1, anything else is corrupt
  uint32_t U32(const char* what);
  int32_t I32(const char* what);
  uint64_t U64(const char* what);
  float F32(const char* what);
  double F64(const char* what);
  std::string String(const char* what);
  // A sequence's element count, each element taking at least `min_element_bytes` on the wire:
  // a count the remaining bytes cannot hold is an error before the caller reserves anything.
  uint32_t Count(const char* what, size_t min_element_bytes);
  // `n` raw bytes (a uint8[] sequence's elements).
  void Bytes(size_t n, const char* what, std::vector<uint8_t>* out);
  // The end of the message: only alignment padding (fewer than 8 bytes) may be left.
  void Finish();

  [[noreturn]] void Fail(const std::string& what) const;
  size_t remaining() const { return size_ - pos_; }

 private:
  void Take(size_t n, const char* what, void* out);  // aligned to n, byte-swapped if needed
  void Need(size_t n, const char* what) const;

  const uint8_t* body_;  // after the encapsulation header
  size_t size_ = 0;      // body bytes
  size_t pos_ = 0;       // relative to the body (CDR alignment origin)
  bool swap_ = false;    // the body's byte order is not the host's
  std::string prefix_;   // "<where>corrupt <type> message: "
};

enum class CdrEndian { kLittle, kBig };

class CdrWriter {
 public:
  explicit CdrWriter(CdrEndian endian = CdrEndian::kLittle);
  void U8(uint8_t v);
  void Bool(bool v) { U8(v ? 1 : 0); }
  void U32(uint32_t v);
  void I32(int32_t v);
  void U64(uint64_t v);
  void F32(float v);
  void F64(double v);
  void String(const std::string& s);
  void Bytes(const std::vector<uint8_t>& bytes);  // the elements of a uint8[] (count written first)
  // The message: encapsulation header and body.
  std::vector<uint8_t> Take() { return std::move(out_); }

 private:
  void Put(const void* v, size_t n);

  std::vector<uint8_t> out_;
  bool swap_ = false;
};

}  // namespace ctlio::io::ros2
