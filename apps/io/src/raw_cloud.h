// A point cloud as a file declares it: named scalar fields at byte offsets of a packed record.
// Private to ctlio_io. The PCD reader (pcd_reader.cc) fills it from the file without PCL, after
// validating the whole file against its header; the PLY reader converts PCL's cloud into it; the
// conversion into ctlio::io::PointCloud (point_cloud_io.cc) is shared.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ctlio::io::detail {

enum class ScalarType {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64
};

size_t ScalarSize(ScalarType type);
bool IsIntegerType(ScalarType type);

struct FieldDesc {
  std::string name;
  ScalarType type = ScalarType::kFloat32;
  size_t count = 1;   // elements of the field per point
  size_t offset = 0;  // byte offset of the first element in a point record
};

struct RawCloud {
  std::vector<FieldDesc> fields;
  size_t point_step = 0;      // bytes per point record
  size_t points = 0;          // number of records in `data`
  std::vector<uint8_t> data;  // points × point_step bytes, little-endian, unaligned
  std::string fields_where;   // where the field list was declared, for messages ("line 3: ")
};

const FieldDesc* FindField(const RawCloud& cloud, const std::string& name);

// Reads element `k` of field `f` of point `i` as double (any scalar type).
double ReadAsDouble(const RawCloud& cloud, size_t i, const FieldDesc& f, size_t k = 0);
// Reads an integer field exactly; false for a float field or a uint64 value above INT64_MAX.
bool ReadAsInt64(const RawCloud& cloud, size_t i, const FieldDesc& f, int64_t* value);

// The readers' shared pieces: "<path>: <what>" and "<path>: line N: <what>" errors, the
// whitespace-separated tokens of a header line, and a whole file's bytes ("file not found",
// "cannot open" and "read error" name the path).
[[noreturn]] void Fail(const std::string& path, const std::string& what);
[[noreturn]] void FailLine(const std::string& path, int line, const std::string& what);
std::vector<std::string> Tokens(const std::string& line);
std::vector<char> ReadFileBytes(const std::string& path);

// Writes the ascii token `tok` as a value of `type` at `out`; false if it does not parse or does
// not fit the type (an integer field holding "nan", or 300 in a uint8, is malformed).
bool StoreAsciiValue(const std::string& tok, ScalarType type, uint8_t* out);

// Reads a PLY file (format ascii, binary_little_endian or binary_big_endian 1.0) without PCL: the
// `vertex` element, first in the file, with scalar properties (list properties of later elements
// are never read). The vertex data must hold exactly the declared count (ascii: one line per
// vertex with one value per property); when vertex is the only element nothing but whitespace
// (ascii) or zero bytes (binary) may follow. Throws "<path>: line N: <what>" or "<path>: <what>".
RawCloud ReadPlyRaw(const std::string& path);

// Reads a PCD file (DATA ascii, binary or binary_compressed) after checking the whole file
// against its header: known keys only, each once, FIELDS/SIZE/TYPE/COUNT of one length, sizes
// valid for their types, WIDTH×HEIGHT = POINTS < 2^31, and a data section holding exactly POINTS
// records (ascii: one line per point with one value per element; binary: POINTS × record bytes;
// binary_compressed: a compressed block that decompresses to exactly that; after the data only
// the zero padding PCL's writer leaves). No allocation is sized from the header before it is
// checked against the file size. Throws "<path>: line N: <what>" or "<path>: <what>".
RawCloud ReadPcdRaw(const std::string& path);

}  // namespace ctlio::io::detail
