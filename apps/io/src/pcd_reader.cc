// PCD reader without PCL: the documented PCD v0.7 subset (DATA ascii, binary, binary_compressed),
// validated against its header before any byte is interpreted. PCL 1.13's reader keeps parsing
// header keywords after DATA, trusts COUNT in compressed data and allocates POINTS records before
// any size check; none of that can be made safe from the outside, so the file is read here.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/point_layout_check.h"
#include "raw_cloud.h"

namespace ctlio::io::detail {
namespace {

constexpr size_t kMaxPoints = (size_t(1) << 31) - 1;  // PCD stores WIDTH as uint32
constexpr size_t kMaxCount = size_t(1) << 16;         // elements per field
constexpr size_t kMaxPointStep = size_t(1) << 20;     // bytes per point record

// A non-negative decimal integer no larger than `max`.
size_t ParseCount(const std::string& path, int line, const std::string& tok, size_t max) {
  if (tok.empty() || tok.size() > 18 || tok.find_first_not_of("0123456789") != std::string::npos) {
    FailLine(path, line, "'" + tok.substr(0, 32) + "' is not a non-negative integer");
  }
  const unsigned long long v = std::strtoull(tok.c_str(), nullptr, 10);
  if (v > max) FailLine(path, line, tok + " exceeds the limit " + std::to_string(max));
  return size_t(v);
}

ScalarType TypeOf(const std::string& path, int line, char type, size_t size) {
  if (type == 'F' && size == 4) return ScalarType::kFloat32;
  if (type == 'F' && size == 8) return ScalarType::kFloat64;
  if (type == 'U' || type == 'I') {
    const bool u = type == 'U';
    switch (size) {
      case 1:
        return u ? ScalarType::kUint8 : ScalarType::kInt8;
      case 2:
        return u ? ScalarType::kUint16 : ScalarType::kInt16;
      case 4:
        return u ? ScalarType::kUint32 : ScalarType::kInt32;
      case 8:
        return u ? ScalarType::kUint64 : ScalarType::kInt64;
      default:
        break;
    }
  }
  FailLine(path, line,
           std::string("TYPE ") + type + " with SIZE " + std::to_string(size) +
               " is not a PCD scalar (F: 4 or 8; U, I: 1, 2, 4 or 8)");
}

// LZF decompression (the format of PCD binary_compressed): a control byte c < 32 copies the next
// c + 1 literal bytes; otherwise length = c >> 5 (7 = extended by the next byte) + 2 bytes are
// copied from distance ((c & 31) << 8) + next byte + 1 back in the output. Every read and write is
// bounds-checked; false unless the input decodes to exactly out->size() bytes.
bool LzfDecompress(const uint8_t* in, size_t in_len, std::vector<uint8_t>* out) {
  size_t ip = 0, op = 0;
  const size_t out_len = out->size();
  while (ip < in_len) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const size_t len = ctrl + 1;
      if (len > in_len - ip || len > out_len - op) return false;
      std::memcpy(out->data() + op, in + ip, len);
      ip += len;
      op += len;
      continue;
    }
    size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_len) return false;
      len += in[ip++];
    }
    if (ip >= in_len) return false;
    const size_t back = (size_t(ctrl & 31) << 8) + in[ip++] + 1;
    len += 2;
    if (back > op || len > out_len - op) return false;
    for (size_t k = 0; k < len; ++k, ++op) (*out)[op] = (*out)[op - back];
  }
  return op == out_len;
}

// PCL's writer pads binary files with zero bytes after the data; anything else after the
// declared records means the header declares fewer points than the data holds.
bool ZeroPadding(const std::vector<char>& bytes, size_t from) {
  return std::all_of(bytes.begin() + std::min(from, bytes.size()), bytes.end(),
                     [](char b) { return b == 0; });
}

struct Header {
  RawCloud cloud;
  std::string data_kind;
  int data_line = 0;
};

// Parses the header lines of `bytes` up to and including DATA; *pos is left at the first data
// byte.
Header ParseHeader(const std::string& path, const std::vector<char>& bytes, size_t* pos) {
  Header h;
  std::vector<std::string> names, types;
  std::vector<size_t> sizes, counts;
  size_t width = 0, height = 1, points = 0;
  bool have_points = false;
  int fields_line = 0;
  std::set<std::string> seen;
  int n = 0;
  while (*pos < bytes.size()) {
    const size_t eol = std::find(bytes.begin() + *pos, bytes.end(), '\n') - bytes.begin();
    std::string line(bytes.begin() + *pos, bytes.begin() + eol);
    *pos = std::min(eol + 1, bytes.size());
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find('\0') != std::string::npos) FailLine(path, n, "NUL byte in the header");
    const std::vector<std::string> tok = Tokens(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    const std::string& key = tok[0];
    static const std::set<std::string> kKeys = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                                                "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
    if (!kKeys.count(key)) FailLine(path, n, "unknown PCD header key '" + key.substr(0, 32) + "'");
    if (!seen.insert(key).second) FailLine(path, n, "header key " + key + " given twice");
    const std::vector<std::string> args(tok.begin() + 1, tok.end());
    auto one = [&](size_t max) {
      if (args.size() != 1) FailLine(path, n, key + " needs one value");
      return ParseCount(path, n, args[0], max);
    };
    if (key == "VERSION" || key == "VIEWPOINT") {
      continue;
    } else if (key == "FIELDS") {
      if (args.empty()) FailLine(path, n, "FIELDS lists no field");
      std::set<std::string> unique(args.begin(), args.end());
      if (unique.size() != args.size()) FailLine(path, n, "FIELDS lists a name twice");
      names = args;
      fields_line = n;
    } else if (key == "SIZE") {
      for (const auto& a : args) sizes.push_back(ParseCount(path, n, a, 8));
    } else if (key == "TYPE") {
      for (const auto& a : args) {
        if (a != "F" && a != "U" && a != "I") FailLine(path, n, "TYPE must be F, U or I");
      }
      types = args;
    } else if (key == "COUNT") {
      for (const auto& a : args) {
        counts.push_back(ParseCount(path, n, a, kMaxCount));
        if (counts.back() == 0) FailLine(path, n, "COUNT must be at least 1");
      }
    } else if (key == "WIDTH") {
      width = one(kMaxPoints);
    } else if (key == "HEIGHT") {
      height = one(kMaxPoints);
    } else if (key == "POINTS") {
      points = one(kMaxPoints);
      have_points = true;
    } else {  // DATA
      if (args.size() != 1 ||
          (args[0] != "ascii" && args[0] != "binary" && args[0] != "binary_compressed")) {
        FailLine(path, n, "DATA must be ascii, binary or binary_compressed");
      }
      h.data_kind = args[0];
      h.data_line = n;
      break;
    }
  }
  if (h.data_kind.empty()) Fail(path, "no DATA line: not a PCD file");
  const int d = h.data_line;
  if (!fields_line || sizes.empty() || types.empty() || !seen.count("WIDTH")) {
    FailLine(path, d, "header lacks FIELDS, SIZE, TYPE or WIDTH before DATA");
  }
  if (sizes.size() != names.size() || types.size() != names.size()) {
    FailLine(path, d, "FIELDS, SIZE and TYPE differ in length");
  }
  if (!counts.empty() && counts.size() != names.size()) {
    FailLine(path, d, "COUNT and FIELDS differ in length");
  }
  if (height != 0 && width > kMaxPoints / height) {
    FailLine(path, d, "WIDTH*HEIGHT exceeds 2^31 - 1 points");
  }
  if (!have_points) points = width * height;
  if (width * height != points) {
    FailLine(path, d,
             "WIDTH*HEIGHT (" + std::to_string(width * height) + ") differs from POINTS (" +
                 std::to_string(points) + ")");
  }
  RawCloud& c = h.cloud;
  for (size_t i = 0; i < names.size(); ++i) {
    FieldDesc f;
    f.name = names[i];
    f.type = TypeOf(path, d, types[i][0], sizes[i]);
    f.count = counts.empty() ? 1 : counts[i];
    f.offset = c.point_step;
    c.point_step += ScalarSize(f.type) * f.count;
    if (c.point_step > kMaxPointStep) FailLine(path, d, "point record larger than 1 MiB");
    c.fields.push_back(f);
  }
  c.points = points;
  c.fields_where = "line " + std::to_string(fields_line) + " (FIELDS): ";
  return h;
}

void ReadAsciiData(const std::string& path, const std::vector<char>& bytes, size_t pos,
                   int first_line, RawCloud* c) {
  size_t elements = 0;
  for (const auto& f : c->fields) elements += f.count;
  std::vector<uint8_t> record(c->point_step);
  size_t read = 0;
  int n = first_line;
  while (pos < bytes.size()) {
    const size_t eol = std::find(bytes.begin() + pos, bytes.end(), '\n') - bytes.begin();
    const std::string line(bytes.begin() + pos, bytes.begin() + eol);
    pos = std::min(eol + 1, bytes.size());
    ++n;
    const std::vector<std::string> tok = Tokens(line);
    if (tok.empty()) continue;
    if (read == c->points) FailLine(path, n, "more points than POINTS " + std::to_string(read));
    if (tok.size() != elements) {
      FailLine(
          path, n,
          "expected " + std::to_string(elements) + " values, found " + std::to_string(tok.size()));
    }
    size_t k = 0;
    for (const auto& f : c->fields) {
      for (size_t e = 0; e < f.count; ++e, ++k) {
        if (!StoreAsciiValue(tok[k], f.type, record.data() + f.offset + e * ScalarSize(f.type))) {
          FailLine(path, n,
                   "value " + std::to_string(k + 1) + " ('" + tok[k].substr(0, 32) +
                       "') is not a valid " + f.name);
        }
      }
    }
    c->data.insert(c->data.end(), record.begin(), record.end());
    ++read;
  }
  if (read != c->points) {
    Fail(path, "ascii data holds " + std::to_string(read) + " points, POINTS declares " +
                   std::to_string(c->points));
  }
}

void ReadCompressedData(const std::string& path, const std::vector<char>& bytes, size_t pos,
                        RawCloud* c) {
  const size_t available = bytes.size() - pos;
  if (available < 8) Fail(path, "binary_compressed data lacks its 8-byte size header");
  uint32_t compressed = 0, uncompressed = 0;
  std::memcpy(&compressed, bytes.data() + pos, 4);
  std::memcpy(&uncompressed, bytes.data() + pos + 4, 4);
  const size_t expected = c->points * c->point_step;
  if (size_t(compressed) > available - 8 || !ZeroPadding(bytes, pos + 8 + compressed)) {
    Fail(path, "binary_compressed block declares " + std::to_string(compressed) +
                   " B, the file holds " + std::to_string(available - 8) + " B");
  }
  if (size_t(uncompressed) != expected) {
    Fail(path, "binary_compressed data decompresses to " + std::to_string(uncompressed) +
                   " B, POINTS × record = " + std::to_string(expected) + " B");
  }
  // LZF expands at most ~88:1 (a 3-byte reference copies 264 bytes): bounds the allocation by the
  // file size before it happens.
  if (expected > 100 * size_t(compressed) + 64) Fail(path, "binary_compressed sizes inconsistent");
  std::vector<uint8_t> soa(expected);
  const auto* in = reinterpret_cast<const uint8_t*>(bytes.data() + pos + 8);
  if (!LzfDecompress(in, compressed, &soa)) Fail(path, "binary_compressed data is corrupt");
  // The decompressed block stores each field for all points in turn; records interleave them.
  c->data.assign(expected, 0);
  size_t block = 0;
  for (const auto& f : c->fields) {
    const size_t bytes_per_point = ScalarSize(f.type) * f.count;
    for (size_t i = 0; i < c->points; ++i) {
      std::memcpy(c->data.data() + i * c->point_step + f.offset,
                  soa.data() + block + i * bytes_per_point, bytes_per_point);
    }
    block += bytes_per_point * c->points;
  }
}

}  // namespace

RawCloud ReadPcdRaw(const std::string& path) {
  const std::vector<char> bytes = ReadFileBytes(path);
  size_t pos = 0;
  Header h = ParseHeader(path, bytes, &pos);
  RawCloud& c = h.cloud;
  if (h.data_kind == "ascii") {
    ReadAsciiData(path, bytes, pos, h.data_line, &c);
  } else if (h.data_kind == "binary") {
    const size_t available = bytes.size() - pos, expected = c.points * c.point_step;
    // Zero padding after the records (PCL's writer) is not data; anything else is.
    const size_t data_bytes =
        ZeroPadding(bytes, pos + expected) ? std::min(available, expected) : available;
    CheckPointBytes(PackedBlock(c.points, c.point_step), data_bytes, path + ": ", "binary data");
    c.data.assign(bytes.begin() + pos, bytes.begin() + pos + expected);
  } else {
    ReadCompressedData(path, bytes, pos, &c);
  }
  return std::move(h.cloud);
}

}  // namespace ctlio::io::detail
