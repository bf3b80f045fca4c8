// PLY reader without PCL (PCL 1.13's PLY parser aborts on an assertion for some malformed files):
// the vertex element with scalar properties, ascii or binary of either byte order, checked
// against its header before any value is read.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/point_layout_check.h"
#include "raw_cloud.h"

namespace ctlio::io::detail {
namespace {

constexpr size_t kMaxVertices = (size_t(1) << 31) - 1;
constexpr size_t kMaxProperties = 1024;

bool PlyType(const std::string& name, ScalarType* type) {
  static const std::map<std::string, ScalarType> kTypes = {
      {"char", ScalarType::kInt8},      {"int8", ScalarType::kInt8},
      {"uchar", ScalarType::kUint8},    {"uint8", ScalarType::kUint8},
      {"short", ScalarType::kInt16},    {"int16", ScalarType::kInt16},
      {"ushort", ScalarType::kUint16},  {"uint16", ScalarType::kUint16},
      {"int", ScalarType::kInt32},      {"int32", ScalarType::kInt32},
      {"uint", ScalarType::kUint32},    {"uint32", ScalarType::kUint32},
      {"float", ScalarType::kFloat32},  {"float32", ScalarType::kFloat32},
      {"double", ScalarType::kFloat64}, {"float64", ScalarType::kFloat64}};
  const auto it = kTypes.find(name);
  if (it == kTypes.end()) return false;
  *type = it->second;
  return true;
}

}  // namespace

RawCloud ReadPlyRaw(const std::string& path) {
  const std::vector<char> bytes = ReadFileBytes(path);
  size_t pos = 0;
  int n = 0;
  auto next_line = [&](std::string* line) {
    if (pos >= bytes.size()) return false;
    const size_t eol = std::find(bytes.begin() + pos, bytes.end(), '\n') - bytes.begin();
    line->assign(bytes.begin() + pos, bytes.begin() + eol);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos = std::min(eol + 1, bytes.size());
    ++n;
    return true;
  };
  std::string line;
  if (!next_line(&line) || line != "ply") Fail(path, "line 1: not a PLY file (no 'ply' magic)");
  std::string format;
  RawCloud c;
  c.fields_where = "header (element vertex properties): ";
  int elements = 0, vertex_line = 0;
  bool in_vertex = false, ended = false;
  std::set<std::string> names;
  while (next_line(&line)) {
    const std::vector<std::string> tok = Tokens(line);
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") {
      ended = true;
      break;
    } else if (tok[0] == "format") {
      if (!format.empty()) FailLine(path, n, "format given twice");
      if (tok.size() != 3 || tok[2] != "1.0" ||
          (tok[1] != "ascii" && tok[1] != "binary_little_endian" &&
           tok[1] != "binary_big_endian")) {
        FailLine(path, n, "format must be ascii, binary_little_endian or binary_big_endian 1.0");
      }
      format = tok[1];
    } else if (tok[0] == "element") {
      if (tok.size() != 3) FailLine(path, n, "element needs a name and a count");
      ++elements;
      in_vertex = tok[1] == "vertex";
      if (in_vertex) {
        if (elements != 1) FailLine(path, n, "the vertex element must come first");
        const std::string& count = tok[2];
        if (count.empty() || count.size() > 10 ||
            count.find_first_not_of("0123456789") != std::string::npos ||
            std::stoull(count) > kMaxVertices) {
          FailLine(path, n, "vertex count '" + count.substr(0, 32) + "' is not in [0, 2^31)");
        }
        c.points = size_t(std::stoull(count));
        vertex_line = n;
      }
    } else if (tok[0] == "property") {
      if (elements == 0) FailLine(path, n, "property before any element");
      if (!in_vertex) continue;  // properties of later elements are never read
      FieldDesc f;
      if (tok.size() != 3 || !PlyType(tok[1], &f.type)) {
        FailLine(path, n, "vertex property must be '<scalar type> <name>' (no lists)");
      }
      if (!names.insert(tok[2]).second) FailLine(path, n, "property '" + tok[2] + "' twice");
      if (c.fields.size() == kMaxProperties) FailLine(path, n, "more than 1024 properties");
      f.name = tok[2];
      f.offset = c.point_step;
      c.point_step += ScalarSize(f.type);
      c.fields.push_back(f);
    } else {
      FailLine(path, n, "unknown PLY header keyword '" + tok[0].substr(0, 32) + "'");
    }
  }
  if (!ended) Fail(path, "no end_header line");
  if (format.empty()) Fail(path, "header has no format line");
  if (!vertex_line) Fail(path, "header has no vertex element");
  if (c.fields.empty() && c.points > 0) FailLine(path, vertex_line, "vertex has no property");
  const bool only_vertex = elements == 1;

  if (format == "ascii") {
    std::vector<uint8_t> record(c.point_step);
    size_t read = 0;
    while (read < c.points && next_line(&line)) {
      const std::vector<std::string> tok = Tokens(line);
      if (tok.empty()) continue;
      if (tok.size() != c.fields.size()) {
        FailLine(path, n,
                 "expected " + std::to_string(c.fields.size()) + " values, found " +
                     std::to_string(tok.size()));
      }
      for (size_t k = 0; k < tok.size(); ++k) {
        if (!StoreAsciiValue(tok[k], c.fields[k].type, record.data() + c.fields[k].offset)) {
          FailLine(path, n,
                   "value '" + tok[k].substr(0, 32) + "' is not a valid " + c.fields[k].name);
        }
      }
      c.data.insert(c.data.end(), record.begin(), record.end());
      ++read;
    }
    if (read != c.points) {
      Fail(path, "ascii data holds " + std::to_string(read) + " vertices, the header declares " +
                     std::to_string(c.points));
    }
    if (only_vertex) {
      while (next_line(&line)) {
        if (!Tokens(line).empty()) FailLine(path, n, "more vertices than the header declares");
      }
    }
    return c;
  }
  const size_t available = bytes.size() - pos, expected = c.points * c.point_step;
  const bool rest_zero = std::all_of(bytes.begin() + std::min(pos + expected, bytes.size()),
                                     bytes.end(), [](char b) { return b == 0; });
  // After the vertices: other elements (never read), or zero padding when vertex is the only one.
  const size_t data_bytes = (only_vertex && !rest_zero) ? available : std::min(available, expected);
  CheckPointBytes(PackedBlock(c.points, c.point_step), data_bytes, path + ": ",
                  "binary vertex data");
  c.data.assign(bytes.begin() + pos, bytes.begin() + pos + expected);
  if (format == "binary_big_endian") {
    for (size_t i = 0; i < c.points; ++i) {
      for (const FieldDesc& f : c.fields) {
        uint8_t* p = c.data.data() + i * c.point_step + f.offset;
        std::reverse(p, p + ScalarSize(f.type));
      }
    }
  }
  return c;
}

}  // namespace ctlio::io::detail
