#include "raw_cloud.h"

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ctlio::io::detail {
namespace {

template <typename T>
T Load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // fields need not be aligned
  return v;
}

}  // namespace

// (raw_cloud.h) Writes the ascii token `tok` as a value of `type` at `out`; false if it does not
// parse or does not fit (an integer field holding "nan" or 300 in a uint8 is malformed, not
// converted).
bool StoreAsciiValue(const std::string& tok, ScalarType type, uint8_t* out) {
  const char* s = tok.c_str();
  char* end = nullptr;
  errno = 0;
  if (!IsIntegerType(type)) {
    const double v = std::strtod(s, &end);
    if (end != s + tok.size()) return false;
    if (type == ScalarType::kFloat64) {
      std::memcpy(out, &v, 8);
    } else {
      const float f = static_cast<float>(v);  // out of range → ±inf, dropped as non-finite
      std::memcpy(out, &f, 4);
    }
    return true;
  }
  auto put = [&](auto v) { std::memcpy(out, &v, sizeof(v)); };
  if (type == ScalarType::kUint64) {
    if (tok[0] == '-') return false;
    const unsigned long long v = std::strtoull(s, &end, 10);
    if (end != s + tok.size() || errno == ERANGE) return false;
    put(uint64_t(v));
    return true;
  }
  const long long v = std::strtoll(s, &end, 10);
  if (end != s + tok.size() || errno == ERANGE) return false;
  auto fits = [&](auto lo, auto hi) { return v >= (long long)lo && v <= (long long)hi; };
  switch (type) {
    case ScalarType::kInt8:
      if (!fits(INT8_MIN, INT8_MAX)) return false;
      put(int8_t(v));
      break;
    case ScalarType::kUint8:
      if (!fits(0, UINT8_MAX)) return false;
      put(uint8_t(v));
      break;
    case ScalarType::kInt16:
      if (!fits(INT16_MIN, INT16_MAX)) return false;
      put(int16_t(v));
      break;
    case ScalarType::kUint16:
      if (!fits(0, UINT16_MAX)) return false;
      put(uint16_t(v));
      break;
    case ScalarType::kInt32:
      if (!fits(INT32_MIN, INT32_MAX)) return false;
      put(int32_t(v));
      break;
    case ScalarType::kUint32:
      if (!fits(0, UINT32_MAX)) return false;
      put(uint32_t(v));
      break;
    default:
      put(int64_t(v));
      break;
  }
  return true;
}

size_t ScalarSize(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    default:
      return 8;
  }
}

bool IsIntegerType(ScalarType type) {
  return type != ScalarType::kFloat32 && type != ScalarType::kFloat64;
}

const FieldDesc* FindField(const RawCloud& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

double ReadAsDouble(const RawCloud& c, size_t i, const FieldDesc& f, size_t k) {
  const uint8_t* p = c.data.data() + i * c.point_step + f.offset + k * ScalarSize(f.type);
  switch (f.type) {
    case ScalarType::kInt8:
      return Load<int8_t>(p);
    case ScalarType::kUint8:
      return Load<uint8_t>(p);
    case ScalarType::kInt16:
      return Load<int16_t>(p);
    case ScalarType::kUint16:
      return Load<uint16_t>(p);
    case ScalarType::kInt32:
      return Load<int32_t>(p);
    case ScalarType::kUint32:
      return Load<uint32_t>(p);
    case ScalarType::kInt64:
      return double(Load<int64_t>(p));
    case ScalarType::kUint64:
      return double(Load<uint64_t>(p));
    case ScalarType::kFloat32:
      return Load<float>(p);
    case ScalarType::kFloat64:
      return Load<double>(p);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

bool ReadAsInt64(const RawCloud& c, size_t i, const FieldDesc& f, int64_t* value) {
  if (!IsIntegerType(f.type)) return false;
  const uint8_t* p = c.data.data() + i * c.point_step + f.offset;
  if (f.type == ScalarType::kUint64) {
    const uint64_t v = Load<uint64_t>(p);
    if (v > uint64_t(std::numeric_limits<int64_t>::max())) return false;
    *value = int64_t(v);
  } else if (f.type == ScalarType::kInt64) {
    *value = Load<int64_t>(p);
  } else {
    *value = int64_t(ReadAsDouble(c, i, f));  // exact for every type up to 32 bits
  }
  return true;
}

void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

void FailLine(const std::string& path, int line, const std::string& what) {
  Fail(path, "line " + std::to_string(line) + ": " + what);
}

std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream ss(line);
  std::vector<std::string> out;
  std::string t;
  while (ss >> t) out.push_back(t);
  return out;
}

std::vector<char> ReadFileBytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) Fail(path, "file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) Fail(path, "read error");
  return bytes;
}

}  // namespace ctlio::io::detail
