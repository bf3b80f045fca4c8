// Point-cloud files: PCD (incl. the Ouster fields of the Newer College Dataset 2020), PLY and
// KITTI-style float32 .bin scans with an optional per-point time file (SPEC §6, §7).
//
// One plain struct for every format. Times follow SPEC §1: int64 nanoseconds in I/O. A cloud
// carries its stamp (the scan start) and, when the file has a time field, the ABSOLUTE time of
// each point (stamp_ns + offset). Every reader throws std::runtime_error naming the file (and the
// header line or point index where it applies) on bad input; nothing is silently dropped except
// non-finite points, which are removed and counted in `dropped_non_finite`.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::io {

struct PointCloud {
  int64_t stamp_ns = 0;           // scan start (the Newer College file-name stamp)
  std::vector<Vec3> points;       // sensor frame, metres
  std::vector<int64_t> times_ns;  // absolute per-point times; empty if the file has none
  std::vector<float> intensity;   // optional (empty if absent)
  std::vector<uint16_t> ring;     // optional beam index (empty if absent)
  size_t dropped_non_finite = 0;  // points removed because x, y or z was NaN/inf

  size_t size() const { return points.size(); }
  bool has_times() const { return !times_ns.empty(); }
  // Per-point time relative to the stamp, in seconds (what a deskewing front end wants).
  double RelativeTime(size_t i) const { return 1e-9 * double(times_ns[i] - stamp_ns); }
};

// Thrown (instead of a plain std::runtime_error) for a well-formed file that cannot be a timed
// scan: a time field of the wrong type, times that are not times, no time field where one is
// required. Dataset readers hand such a scan on as an empty one (documented recovery); malformed
// files stay errors.
class UnusableCloudError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The per-point time field is detected from the field names and types by the drivers'
// conventions of point_fields.h (Ouster `t`, Livox `offset_time`, Velodyne `time`, Hesai/Robosense
// and Livox `timestamp`), the same detection as for ROS PointCloud2 messages; `time` overrides it.
struct TimeFieldOptions;
struct ReadOptions {
  int64_t stamp_ns = 0;  // the scan stamp (PCD/PLY carry none; Newer College has it in the name)
  bool require_time = false;               // throw if the file has no per-point time field
  const TimeFieldOptions* time = nullptr;  // override of the detected time convention (optional)
};

// PCD (ascii, binary, binary_compressed), read by ctlio itself after the whole file has been
// checked against its header (sizes, counts, data length, WIDTH×HEIGHT = POINTS < 2^31).
PointCloud ReadPcd(const std::string& path, const ReadOptions& options = {});
// PLY (ascii, binary little or big endian), read by ctlio itself (the vertex element's scalar
// properties, checked against the header); same fields as PCD.
PointCloud ReadPly(const std::string& path, const ReadOptions& options = {});
// Dispatch on the extension (.pcd, .ply, .bin).
PointCloud ReadPointCloud(const std::string& path, const ReadOptions& options = {});

// KITTI-style scan: little-endian float32 records of `floats_per_point` values (4 = x y z
// reflectance as in KITTI; 3 = x y z as in gtsam_points' dumps). If `times_path` is non-empty it is
// read as one float32 per point, seconds since the stamp (gtsam_points' times_*.bin), and must have
// exactly one value per point.
PointCloud ReadKittiBin(const std::string& path, int floats_per_point = 4,
                        const std::string& times_path = "", int64_t stamp_ns = 0);

// Writers. WritePcd writes binary PCD with the Ouster OS1 fields of the Newer College Dataset:
// x y z intensity (float32), t (uint32 ns since stamp), reflectivity (uint16), ring (uint8),
// noise (uint16), range (uint32, mm). Clouds without times get t = 0.
void WritePcd(const std::string& path, const PointCloud& cloud);
// Binary little-endian PLY with x y z (float) and, when present, t (uint32 ns since stamp).
void WritePly(const std::string& path, const PointCloud& cloud);
// KITTI .bin (x y z reflectance float32); if `times_path` is non-empty, float32 seconds since
// stamp.
void WriteKittiBin(const std::string& path, const PointCloud& cloud,
                   const std::string& times_path = "");

}  // namespace ctlio::io
