#include "ctlio/io/point_cloud_io.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/point_fields.h"

namespace ctlio::io {
namespace {

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

void RequireFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) Fail(path, "file not found");
}

// Validates a PCD header line by line before PCL sees the file: PCL's reader reports no line
// numbers and crashes on some malformed headers. Returns the 1-based line of FIELDS.
int CheckPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open");
  std::string line;
  int fields_line = 0;
  size_t n_fields = 0, width = 0, height = 0, points = 0, point_step = 0;
  std::vector<size_t> sizes, counts;
  bool have_width = false, have_height = false, have_size = false, have_type = false;
  auto fail = [&](int n, const std::string& what) -> void {
    Fail(path, "line " + std::to_string(n) + ": " + what);
  };
  auto numbers = [&](std::istringstream& ss, int n) {
    std::vector<size_t> v;
    std::string tok;
    while (ss >> tok) {
      try {
        size_t used = 0;
        const long long x = std::stoll(tok, &used);
        if (used != tok.size() || x < 0) throw std::invalid_argument(tok);
        v.push_back(size_t(x));
      } catch (const std::exception&) {
        fail(n, "'" + tok + "' is not a non-negative integer");
      }
    }
    return v;
  };
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    std::string key;
    ss >> key;
    if (key == "VERSION" || key == "VIEWPOINT") {
      continue;
    } else if (key == "FIELDS") {
      fields_line = n;
      std::string f;
      while (ss >> f) ++n_fields;
      if (n_fields == 0) fail(n, "FIELDS lists no field");
    } else if (key == "SIZE") {
      sizes = numbers(ss, n);
      have_size = true;
      for (size_t s : sizes) {
        if (s != 1 && s != 2 && s != 4 && s != 8) fail(n, "SIZE must be 1, 2, 4 or 8");
      }
    } else if (key == "TYPE") {
      std::string t;
      size_t k = 0;
      while (ss >> t) {
        ++k;
        if (t != "F" && t != "U" && t != "I") fail(n, "TYPE must be F, U or I, not '" + t + "'");
      }
      have_type = k > 0;
    } else if (key == "COUNT") {
      counts = numbers(ss, n);
    } else if (key == "WIDTH") {
      const auto v = numbers(ss, n);
      if (v.size() != 1) fail(n, "WIDTH needs one value");
      width = v[0];
      have_width = true;
    } else if (key == "HEIGHT") {
      const auto v = numbers(ss, n);
      if (v.size() != 1) fail(n, "HEIGHT needs one value");
      height = v[0];
      have_height = true;
    } else if (key == "POINTS") {
      const auto v = numbers(ss, n);
      if (v.size() != 1) fail(n, "POINTS needs one value");
      points = v[0];
    } else if (key == "DATA") {
      std::string kind;
      ss >> kind;
      if (kind != "ascii" && kind != "binary" && kind != "binary_compressed") {
        fail(n, "DATA must be ascii, binary or binary_compressed, not '" + kind + "'");
      }
      if (!fields_line || !have_size || !have_type || !have_width) {
        fail(n, "header lacks FIELDS, SIZE, TYPE or WIDTH before DATA");
      }
      if (sizes.size() != n_fields) fail(n, "SIZE and FIELDS differ in length");
      if (!counts.empty() && counts.size() != n_fields)
        fail(n, "COUNT and FIELDS differ in length");
      if (!have_height) height = 1;
      if (width * height != points && points != 0) {
        fail(n, "WIDTH*HEIGHT (" + std::to_string(width * height) + ") differs from POINTS (" +
                    std::to_string(points) + ")");
      }
      for (size_t i = 0; i < n_fields; ++i)
        point_step += sizes[i] * (counts.empty() ? 1 : counts[i]);
      if (kind == "binary") {
        const std::streamoff header_end = in.tellg();
        in.seekg(0, std::ios::end);
        const std::streamoff bytes = in.tellg() - header_end;
        if (bytes < std::streamoff(width * height * point_step)) {
          fail(n, "binary data holds " + std::to_string(bytes) + " B, " +
                      std::to_string(width * height * point_step) + " B expected");
        }
      }
      return fields_line;
    } else {
      fail(n, "unknown PCD header key '" + key.substr(0, 32) + "'");
    }
  }
  Fail(path, "no DATA line: not a PCD file");
}

const pcl::PCLPointField* FindField(const pcl::PCLPointCloud2& c, const std::string& name) {
  for (const auto& f : c.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

template <typename T>
double Load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // fields need not be aligned
  return static_cast<double>(v);
}

// Reads a scalar field of any PCL numeric type as double.
double ReadScalar(const uint8_t* p, uint8_t type) {
  switch (type) {
    case pcl::PCLPointField::INT8:
      return Load<int8_t>(p);
    case pcl::PCLPointField::UINT8:
      return Load<uint8_t>(p);
    case pcl::PCLPointField::INT16:
      return Load<int16_t>(p);
    case pcl::PCLPointField::UINT16:
      return Load<uint16_t>(p);
    case pcl::PCLPointField::INT32:
      return Load<int32_t>(p);
    case pcl::PCLPointField::UINT32:
      return Load<uint32_t>(p);
    case pcl::PCLPointField::FLOAT32:
      return Load<float>(p);
    case pcl::PCLPointField::FLOAT64:
      return Load<double>(p);
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

PointCloud FromCloud2(const pcl::PCLPointCloud2& c, const std::string& path,
                      const ReadOptions& options, const std::string& fields_where) {
  const auto* fx = FindField(c, "x");
  const auto* fy = FindField(c, "y");
  const auto* fz = FindField(c, "z");
  if (!fx || !fy || !fz) Fail(path, fields_where + "no x, y and z fields");
  // The per-point time convention: one detection for PCD and PointCloud2 (point_fields.h).
  std::vector<PointField> fields;
  for (const auto& f : c.fields) fields.push_back({f.name, f.datatype, f.offset, f.count});
  const PointLayout layout = DetectPointLayout(
      fields, 0, options.time ? *options.time : TimeFieldOptions{}, path + ": " + fields_where);
  if (options.require_time && !layout.time) {
    Fail(path, fields_where + "no per-point time field (expected 't', 'offset_time', 'time' or " +
                   "'timestamp'; fields found: " + DescribeFields(fields) + ")");
  }
  const auto* fi = FindField(c, "intensity");
  const auto* fr = FindField(c, "ring");
  const size_t n = size_t(c.width) * c.height;
  if (c.data.size() < n * c.point_step) Fail(path, "data section shorter than WIDTH*HEIGHT points");

  PointCloud out;
  out.stamp_ns = options.stamp_ns;
  out.points.reserve(n);
  if (layout.time) out.times_ns.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = c.data.data() + i * c.point_step;
    const Vec3 x(ReadScalar(p + fx->offset, fx->datatype), ReadScalar(p + fy->offset, fy->datatype),
                 ReadScalar(p + fz->offset, fz->datatype));
    if (!x.allFinite()) {
      ++out.dropped_non_finite;
      continue;
    }
    out.points.push_back(x);
    if (layout.time) {
      int64_t t = 0;
      if (!PointTimeNs(layout, p, options.stamp_ns, &t))
        Fail(path, "point " + std::to_string(i) + ": non-finite time");
      out.times_ns.push_back(t);
    }
    if (fi) out.intensity.push_back(float(ReadScalar(p + fi->offset, fi->datatype)));
    if (fr) out.ring.push_back(uint16_t(ReadScalar(p + fr->offset, fr->datatype)));
  }
  return out;
}

template <typename T>
void AddField(pcl::PCLPointCloud2* c, const std::string& name, uint8_t type) {
  pcl::PCLPointField f;
  f.name = name;
  f.offset = c->point_step;
  f.datatype = type;
  f.count = 1;
  c->fields.push_back(f);
  c->point_step += sizeof(T);
}

template <typename T>
void Put(uint8_t* p, const pcl::PCLPointField& f, T v) {
  std::memcpy(p + f.offset, &v, sizeof(T));
}

// One unorganised row of n zeroed points with the fields added so far.
void AllocatePoints(pcl::PCLPointCloud2* c, size_t n) {
  c->width = uint32_t(n);
  c->height = 1;
  c->is_dense = true;
  c->row_step = c->point_step * c->width;
  c->data.assign(size_t(c->row_step), 0);
}

uint32_t OffsetNs(const PointCloud& cloud, size_t i, const std::string& path) {
  if (!cloud.has_times()) return 0;
  const int64_t dt = cloud.times_ns[i] - cloud.stamp_ns;
  if (dt < 0 || dt > int64_t(std::numeric_limits<uint32_t>::max())) {
    Fail(path, "point " + std::to_string(i) + " time is not within 4.29 s after the stamp");
  }
  return uint32_t(dt);
}

void CheckCloud(const PointCloud& cloud, const std::string& path) {
  if (cloud.has_times() && cloud.times_ns.size() != cloud.points.size()) {
    Fail(path, "cannot write: times_ns and points differ in size");
  }
}

}  // namespace

PointCloud ReadPcd(const std::string& path, const ReadOptions& options) {
  RequireFile(path);
  pcl::PCLPointCloud2 c;
  const int line = CheckPcdHeader(path);
  pcl::PCDReader reader;
  if (reader.read(path, c) < 0) Fail(path, "PCL could not parse the PCD data");
  return FromCloud2(c, path, options, "line " + std::to_string(line) + " (FIELDS): ");
}

PointCloud ReadPly(const std::string& path, const ReadOptions& options) {
  RequireFile(path);
  pcl::PCLPointCloud2 c;
  pcl::PLYReader reader;
  if (reader.read(path, c) < 0) Fail(path, "PCL could not parse the PLY header or data");
  return FromCloud2(c, path, options, "header (element vertex properties): ");
}

PointCloud ReadPointCloud(const std::string& path, const ReadOptions& options) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".pcd") return ReadPcd(path, options);
  if (ext == ".ply") return ReadPly(path, options);
  if (ext == ".bin") {
    if (options.require_time) Fail(path, "a .bin scan has no time field (use ReadKittiBin)");
    return ReadKittiBin(path, 4, "", options.stamp_ns);
  }
  Fail(path, "unknown point-cloud extension '" + ext + "' (expected .pcd, .ply or .bin)");
}

namespace {
std::vector<char> ReadBytes(const std::string& path) {
  RequireFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open");
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
}  // namespace

PointCloud ReadKittiBin(const std::string& path, int floats_per_point,
                        const std::string& times_path, int64_t stamp_ns) {
  if (floats_per_point < 3) Fail(path, "floats_per_point must be at least 3");
  const std::vector<char> bytes = ReadBytes(path);
  const size_t record = sizeof(float) * size_t(floats_per_point);
  if (bytes.size() % record != 0) {
    Fail(path, "size " + std::to_string(bytes.size()) + " B is not a multiple of " +
                   std::to_string(record) + " B per point");
  }
  const size_t n = bytes.size() / record;
  std::vector<float> times;
  if (!times_path.empty()) {
    const std::vector<char> tb = ReadBytes(times_path);
    if (tb.size() != n * sizeof(float)) {
      Fail(times_path, "has " + std::to_string(tb.size() / sizeof(float)) + " times for " +
                           std::to_string(n) + " points in " + path);
    }
    times.resize(n);
    std::memcpy(times.data(), tb.data(), tb.size());
  }
  PointCloud out;
  out.stamp_ns = stamp_ns;
  out.points.reserve(n);
  if (floats_per_point >= 4) out.intensity.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    float v[4] = {0, 0, 0, 0};
    std::memcpy(v, bytes.data() + i * record, sizeof(float) * std::min(floats_per_point, 4));
    const Vec3 x(v[0], v[1], v[2]);
    if (!x.allFinite()) {
      ++out.dropped_non_finite;
      continue;
    }
    out.points.push_back(x);
    if (floats_per_point >= 4) out.intensity.push_back(v[3]);
    if (!times.empty()) {
      if (!std::isfinite(times[i])) Fail(times_path, "value " + std::to_string(i) + " not finite");
      out.times_ns.push_back(stamp_ns + std::llround(double(times[i]) * 1e9));
    }
  }
  return out;
}

void WritePcd(const std::string& path, const PointCloud& cloud) {
  CheckCloud(cloud, path);
  pcl::PCLPointCloud2 c;
  using F = pcl::PCLPointField;
  AddField<float>(&c, "x", F::FLOAT32);
  AddField<float>(&c, "y", F::FLOAT32);
  AddField<float>(&c, "z", F::FLOAT32);
  AddField<float>(&c, "intensity", F::FLOAT32);
  AddField<uint32_t>(&c, "t", F::UINT32);
  AddField<uint16_t>(&c, "reflectivity", F::UINT16);
  AddField<uint8_t>(&c, "ring", F::UINT8);
  AddField<uint16_t>(&c, "noise", F::UINT16);
  AddField<uint32_t>(&c, "range", F::UINT32);
  const size_t n = cloud.size();
  AllocatePoints(&c, n);
  for (size_t i = 0; i < n; ++i) {
    uint8_t* p = c.data.data() + i * c.point_step;
    const Vec3& x = cloud.points[i];
    Put<float>(p, c.fields[0], float(x.x()));
    Put<float>(p, c.fields[1], float(x.y()));
    Put<float>(p, c.fields[2], float(x.z()));
    Put<float>(p, c.fields[3], cloud.intensity.size() == n ? cloud.intensity[i] : 0.f);
    Put<uint32_t>(p, c.fields[4], OffsetNs(cloud, i, path));
    Put<uint8_t>(p, c.fields[6], cloud.ring.size() == n ? uint8_t(cloud.ring[i]) : uint8_t(0));
    Put<uint32_t>(p, c.fields[8], uint32_t(std::llround(x.norm() * 1000.0)));
  }
  pcl::PCDWriter writer;
  if (writer.writeBinary(path, c) < 0) Fail(path, "PCL could not write the file");
}

void WritePly(const std::string& path, const PointCloud& cloud) {
  CheckCloud(cloud, path);
  pcl::PCLPointCloud2 c;
  using F = pcl::PCLPointField;
  AddField<float>(&c, "x", F::FLOAT32);
  AddField<float>(&c, "y", F::FLOAT32);
  AddField<float>(&c, "z", F::FLOAT32);
  if (cloud.has_times()) AddField<uint32_t>(&c, "t", F::UINT32);
  const size_t n = cloud.size();
  AllocatePoints(&c, n);
  for (size_t i = 0; i < n; ++i) {
    uint8_t* p = c.data.data() + i * c.point_step;
    for (int k = 0; k < 3; ++k) Put<float>(p, c.fields[k], float(cloud.points[i][k]));
    if (cloud.has_times()) Put<uint32_t>(p, c.fields[3], OffsetNs(cloud, i, path));
  }
  pcl::PLYWriter writer;
  if (writer.writeBinary(path, c, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(),
                         /*use_camera=*/false) < 0)
    Fail(path, "PCL could not write the file");
}

void WriteKittiBin(const std::string& path, const PointCloud& cloud,
                   const std::string& times_path) {
  CheckCloud(cloud, path);
  std::ofstream out(path, std::ios::binary);
  if (!out) Fail(path, "cannot open for writing");
  const size_t n = cloud.size();
  for (size_t i = 0; i < n; ++i) {
    const float v[4] = {float(cloud.points[i].x()), float(cloud.points[i].y()),
                        float(cloud.points[i].z()),
                        cloud.intensity.size() == n ? cloud.intensity[i] : 0.f};
    out.write(reinterpret_cast<const char*>(v), sizeof(v));
  }
  if (!out) Fail(path, "write failed");
  if (!times_path.empty()) {
    std::ofstream tout(times_path, std::ios::binary);
    if (!tout) Fail(times_path, "cannot open for writing");
    for (size_t i = 0; i < n; ++i) {
      const float s =
          cloud.has_times() ? float(1e-9 * double(cloud.times_ns[i] - cloud.stamp_ns)) : 0.f;
      tout.write(reinterpret_cast<const char*>(&s), sizeof(s));
    }
    if (!tout) Fail(times_path, "write failed");
  }
}

}  // namespace ctlio::io
