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

#include "ctlio/io/checked_output.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/point_fields.h"
#include "raw_cloud.h"

namespace ctlio::io {
namespace {

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

void RequireFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) Fail(path, "file not found");
}

// The raw field list in point_fields' terms (PointCloud2 datatype codes), so that PCD and PLY
// detect per-point times exactly as ROS PointCloud2 messages do. 64-bit integer fields, which
// PointCloud2 cannot express, get code 0: no time convention matches them.
std::vector<PointField> LayoutFields(const detail::RawCloud& c) {
  std::vector<PointField> out;
  out.reserve(c.fields.size());
  for (const detail::FieldDesc& f : c.fields) {
    uint8_t code = 0;
    switch (f.type) {
      case detail::ScalarType::kInt8:
        code = kInt8;
        break;
      case detail::ScalarType::kUint8:
        code = kUInt8;
        break;
      case detail::ScalarType::kInt16:
        code = kInt16;
        break;
      case detail::ScalarType::kUint16:
        code = kUInt16;
        break;
      case detail::ScalarType::kInt32:
        code = kInt32;
        break;
      case detail::ScalarType::kUint32:
        code = kUInt32;
        break;
      case detail::ScalarType::kFloat32:
        code = kFloat32;
        break;
      case detail::ScalarType::kFloat64:
        code = kFloat64;
        break;
      default:
        break;
    }
    out.push_back({f.name, code, uint32_t(f.offset), uint32_t(f.count)});
  }
  return out;
}

PointCloud FromRaw(const detail::RawCloud& c, const std::string& path, const ReadOptions& options) {
  const std::string& where = c.fields_where;
  const auto* fx = detail::FindField(c, "x");
  const auto* fy = detail::FindField(c, "y");
  const auto* fz = detail::FindField(c, "z");
  if (!fx || !fy || !fz) Fail(path, where + "no x, y and z fields");
  const std::vector<PointField> fields = LayoutFields(c);
  PointLayout layout;
  try {
    layout =
        DetectPointLayout(fields, uint32_t(c.point_step),
                          options.time ? *options.time : TimeFieldOptions{}, path + ": " + where);
  } catch (const std::exception& e) {
    // A time field of a type no driver writes: the file is well formed but not a timed scan.
    throw UnusableCloudError(e.what());
  }
  if (options.require_time && !layout.time) {
    throw UnusableCloudError(path + ": " + where +
                             "no per-point time field (expected 't', 'offset_time', 'time' or "
                             "'timestamp'; fields found: " +
                             DescribeFields(fields) + ")");
  }
  const auto* fi = detail::FindField(c, "intensity");
  const auto* fr = detail::FindField(c, "ring");
  if (c.data.size() < c.points * c.point_step) Fail(path, "data section shorter than its points");

  PointCloud out;
  out.stamp_ns = options.stamp_ns;
  out.points.reserve(c.points);
  if (layout.time) out.times_ns.reserve(c.points);
  for (size_t i = 0; i < c.points; ++i) {
    const Vec3 x(detail::ReadAsDouble(c, i, *fx), detail::ReadAsDouble(c, i, *fy),
                 detail::ReadAsDouble(c, i, *fz));
    if (!x.allFinite()) {
      ++out.dropped_non_finite;
      continue;
    }
    out.points.push_back(x);
    if (layout.time) {
      int64_t t = 0;
      if (!PointTimeNs(layout, c.data.data() + i * c.point_step, options.stamp_ns, &t)) {
        throw UnusableCloudError(path + ": point " + std::to_string(i) +
                                 ": time is not a valid time (not finite or outside int64 ns)");
      }
      out.times_ns.push_back(t);
    }
    if (fi) {
      const double v = detail::ReadAsDouble(c, i, *fi);
      out.intensity.push_back(std::abs(v) <= std::numeric_limits<float>::max() ? float(v) : NAN);
    }
    if (fr) {
      const double v = detail::ReadAsDouble(c, i, *fr);
      if (!(v >= 0.0 && v <= 65535.0)) {  // also false for NaN: never cast it to an integer
        Fail(path, "point " + std::to_string(i) + ": ring " + std::to_string(v) +
                       " is not in [0, 65535]");
      }
      out.ring.push_back(uint16_t(v));
    }
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
  return FromRaw(detail::ReadPcdRaw(path), path, options);
}

PointCloud ReadPly(const std::string& path, const ReadOptions& options) {
  RequireFile(path);
  return FromRaw(detail::ReadPlyRaw(path), path, options);
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
    if (n > 0) std::memcpy(times.data(), tb.data(), tb.size());
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
      int64_t offset = 0, t = 0;
      if (!SecondsToNs(double(times[i]), &offset) || __builtin_add_overflow(stamp_ns, offset, &t)) {
        throw UnusableCloudError(times_path + ": value " + std::to_string(i) + " (" +
                                 std::to_string(times[i]) + ") is not a valid time");
      }
      out.times_ns.push_back(t);
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
  std::ofstream out = OpenForWriting(path, std::ios::binary | std::ios::trunc);
  const size_t n = cloud.size();
  for (size_t i = 0; i < n; ++i) {
    const float v[4] = {float(cloud.points[i].x()), float(cloud.points[i].y()),
                        float(cloud.points[i].z()),
                        cloud.intensity.size() == n ? cloud.intensity[i] : 0.f};
    out.write(reinterpret_cast<const char*>(v), sizeof(v));
  }
  CloseChecked(out, path);
  if (!times_path.empty()) {
    std::ofstream tout = OpenForWriting(times_path, std::ios::binary | std::ios::trunc);
    for (size_t i = 0; i < n; ++i) {
      const float s =
          cloud.has_times() ? float(1e-9 * double(cloud.times_ns[i] - cloud.stamp_ns)) : 0.f;
      tout.write(reinterpret_cast<const char*>(&s), sizeof(s));
    }
    CloseChecked(tout, times_path);
  }
}

}  // namespace ctlio::io
