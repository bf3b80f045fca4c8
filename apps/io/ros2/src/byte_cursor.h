// Bounded little-endian reading of MCAP records (https://mcap.dev/spec, "Serialization"): every
// integer, string, byte array and map is checked against the bytes left before it is read or
// anything is allocated, so a corrupt length is an error naming the file and byte offset.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::io::ros2 {

class ByteCursor {
 public:
  // `data`/`size`: the bytes of one record (or chunk); `file_offset`: where data[0] is in the file
  // (for errors; for bytes inside a decompressed chunk, the chunk's offset and `where` says so).
  ByteCursor(const uint8_t* data, size_t size, const std::string& file, uint64_t file_offset,
             const std::string& where = "")
      : data_(data), size_(size), file_(file), file_offset_(file_offset), where_(where) {}

  size_t pos() const { return pos_; }
  size_t left() const { return size_ - pos_; }
  bool empty() const { return pos_ == size_; }
  const uint8_t* here() const { return data_ + pos_; }

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(file_ + ": not a valid MCAP file (truncated or corrupted?): " + what +
                             " at byte " + std::to_string(file_offset_ + pos_) + where_);
  }
  void Need(uint64_t n, const char* what) const {
    if (n > left()) {
      Fail(std::string(what) + " of " + std::to_string(n) + " bytes where " +
           std::to_string(left()) + " remain");
    }
  }
  template <typename T>
  T Int(const char* what) {
    Need(sizeof(T), what);
    T v = 0;
    for (size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<T>(static_cast<T>(data_[pos_ + i]) << (8 * i));
    pos_ += sizeof(T);
    return v;
  }
  uint8_t U8(const char* what) { return Int<uint8_t>(what); }
  uint16_t U16(const char* what) { return Int<uint16_t>(what); }
  uint32_t U32(const char* what) { return Int<uint32_t>(what); }
  uint64_t U64(const char* what) { return Int<uint64_t>(what); }
  // Times are uint64 nanoseconds; ctlio's are int64 (years 1678–2262).
  int64_t Time(const char* what) {
    const uint64_t t = U64(what);
    if (t > static_cast<uint64_t>(INT64_MAX)) {
      pos_ -= 8;
      Fail(std::string(what) + " " + std::to_string(t) + " beyond year 2262");
    }
    return static_cast<int64_t>(t);
  }
  std::string String(const char* what) {
    const uint32_t n = U32(what);
    Need(n, what);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  // A byte range of `n` bytes (returned as the cursor over it), advancing past it.
  ByteCursor Sub(uint64_t n, const char* what) {
    Need(n, what);
    ByteCursor c(data_ + pos_, static_cast<size_t>(n), file_, file_offset_ + pos_, where_);
    pos_ += static_cast<size_t>(n);
    return c;
  }
  void Skip(uint64_t n, const char* what) {
    Need(n, what);
    pos_ += static_cast<size_t>(n);
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  const std::string& file_;
  uint64_t file_offset_;
  std::string where_;
};

// Little-endian appending, for the writer.
class ByteWriter {
 public:
  std::vector<uint8_t>& bytes() { return b_; }
  void U8(uint8_t v) { b_.push_back(v); }
  void U16(uint16_t v) { Int(v); }
  void U32(uint32_t v) { Int(v); }
  void U64(uint64_t v) { Int(v); }
  void String(const std::string& s) {
    U32(static_cast<uint32_t>(s.size()));
    b_.insert(b_.end(), s.begin(), s.end());
  }
  void Bytes(const uint8_t* p, size_t n) { b_.insert(b_.end(), p, p + n); }
  void Bytes(const std::vector<uint8_t>& v) { b_.insert(b_.end(), v.begin(), v.end()); }
  // Overwrites 4 or 8 bytes at `at` (a length prefix known only after its content).
  void PatchU32(size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) b_[at + i] = static_cast<uint8_t>(v >> (8 * i));
  }
  void PatchU64(size_t at, uint64_t v) {
    for (int i = 0; i < 8; ++i) b_[at + i] = static_cast<uint8_t>(v >> (8 * i));
  }

 private:
  template <typename T>
  void Int(T v) {
    for (size_t i = 0; i < sizeof(T); ++i) b_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t> b_;
};

}  // namespace ctlio::io::ros2
