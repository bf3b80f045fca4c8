#include "ctlio/io/cdr.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace ctlio::io::ros2 {
namespace {

constexpr size_t kHeaderBytes = 4;

bool HostIsLittle() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

void Reverse(void* v, size_t n) {
  auto* b = static_cast<uint8_t*>(v);
  std::reverse(b, b + n);
}

}  // namespace

CdrReader::CdrReader(const uint8_t* data, size_t size, const std::string& where,
                     const std::string& type)
    : body_(data + std::min(size, kHeaderBytes)),
      size_(size - std::min(size, kHeaderBytes)),
      prefix_(where + "corrupt " + type + " message: ") {
  if (size < kHeaderBytes) {
    Fail(std::to_string(size) + " bytes, shorter than the 4-byte encapsulation header");
  }
  // Representation identifiers (DDS-XTypes 1.3 Table 60): CDR_BE {0,0}, CDR_LE {0,1}; the
  // parameter-list and XCDR2 encodings are not what rosbag2 records for these types.
  if (data[0] != 0 || data[1] > 1) {
    Fail("encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) +
         " is not CDR_LE (0,1) or CDR_BE (0,0)");
  }
  swap_ = (data[1] == 1) != HostIsLittle();
}

void CdrReader::Fail(const std::string& what) const {
  throw std::runtime_error(prefix_ + what + " (at byte " + std::to_string(kHeaderBytes + pos_) +
                           ")");
}

void CdrReader::Need(size_t n, const char* what) const {
  if (n > size_ - pos_) {
    Fail(std::string(what) + ": needs " + std::to_string(n) + " bytes, " +
         std::to_string(size_ - pos_) + " left");
  }
}

void CdrReader::Take(size_t n, const char* what, void* out) {
  const size_t pad = (n - pos_ % n) % n;
  Need(pad + n, what);
  pos_ += pad;
  std::memcpy(out, body_ + pos_, n);
  if (swap_) Reverse(out, n);
  pos_ += n;
}

uint8_t CdrReader::U8(const char* what) {
  uint8_t v = 0;
  Take(1, what, &v);
  return v;
}

bool CdrReader::Bool(const char* what) {
  const uint8_t v = U8(what);
  if (v > 1) Fail(std::string(what) + ": boolean byte " + std::to_string(v) + " is not 0 or 1");
  return v == 1;
}

uint32_t CdrReader::U32(const char* what) {
  uint32_t v = 0;
  Take(4, what, &v);
  return v;
}

int32_t CdrReader::I32(const char* what) {
  int32_t v = 0;
  Take(4, what, &v);
  return v;
}

uint64_t CdrReader::U64(const char* what) {
  uint64_t v = 0;
  Take(8, what, &v);
  return v;
}

float CdrReader::F32(const char* what) {
  float v = 0;
  Take(4, what, &v);
  return v;
}

double CdrReader::F64(const char* what) {
  double v = 0;
  Take(8, what, &v);
  return v;
}

std::string CdrReader::String(const char* what) {
  const uint32_t n = U32(what);
  // n counts the terminating NUL; some writers give 0 for the empty string.
  if (n == 0) return {};
  Need(n, what);
  if (body_[pos_ + n - 1] != 0) Fail(std::string(what) + ": string not NUL-terminated");
  std::string s(reinterpret_cast<const char*>(body_ + pos_), n - 1);
  pos_ += n;
  return s;
}

uint32_t CdrReader::Count(const char* what, size_t min_element_bytes) {
  const uint32_t n = U32(what);
  if (min_element_bytes > 0 && n > (size_ - pos_) / min_element_bytes) {
    Fail(std::string(what) + ": " + std::to_string(n) + " elements of at least " +
         std::to_string(min_element_bytes) + " bytes, " + std::to_string(size_ - pos_) +
         " bytes left");
  }
  return n;
}

void CdrReader::Bytes(size_t n, const char* what, std::vector<uint8_t>* out) {
  Need(n, what);
  out->assign(body_ + pos_, body_ + pos_ + n);
  pos_ += n;
}

void CdrReader::Finish() {
  // Serializers may pad the message to a multiple of 4 or 8 bytes.
  if (size_ - pos_ >= 8) {
    Fail(std::to_string(size_ - pos_) + " bytes left over after the message");
  }
}

CdrWriter::CdrWriter(CdrEndian endian) : swap_((endian == CdrEndian::kLittle) != HostIsLittle()) {
  out_ = {0, uint8_t(endian == CdrEndian::kLittle ? 1 : 0), 0, 0};
}

void CdrWriter::Put(const void* v, size_t n) {
  while ((out_.size() - kHeaderBytes) % n != 0) out_.push_back(0);
  const size_t at = out_.size();
  out_.resize(at + n);
  std::memcpy(out_.data() + at, v, n);
  if (swap_) Reverse(out_.data() + at, n);
}

void CdrWriter::U8(uint8_t v) { Put(&v, 1); }
void CdrWriter::U32(uint32_t v) { Put(&v, 4); }
void CdrWriter::I32(int32_t v) { Put(&v, 4); }
void CdrWriter::U64(uint64_t v) { Put(&v, 8); }
void CdrWriter::F32(float v) { Put(&v, 4); }
void CdrWriter::F64(double v) { Put(&v, 8); }

void CdrWriter::String(const std::string& s) {
  if (s.size() >= UINT32_MAX)
    throw std::runtime_error("CDR: string of " + std::to_string(s.size()) + " bytes");
  U32(uint32_t(s.size() + 1));
  out_.insert(out_.end(), s.begin(), s.end());
  out_.push_back(0);
}

void CdrWriter::Bytes(const std::vector<uint8_t>& bytes) {
  if (bytes.size() > UINT32_MAX) {
    throw std::runtime_error("CDR: sequence of " + std::to_string(bytes.size()) + " bytes");
  }
  U32(uint32_t(bytes.size()));
  out_.insert(out_.end(), bytes.begin(), bytes.end());
}

}  // namespace ctlio::io::ros2
