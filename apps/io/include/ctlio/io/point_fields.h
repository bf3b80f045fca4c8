// Per-point field layouts of lidar clouds (PCD files and sensor_msgs/PointCloud2 messages) and the
// one detection of the per-point time field that serves both.
//
// A layout is a list of (name, datatype, offset, count) as in PCD headers and PointCloud2. The
// per-point time is the field that varies most between drivers: its name does not fix its unit
// (Hesai's `timestamp` is seconds, Livox driver 2's `timestamp` is nanoseconds), so a convention
// is matched on the name AND the datatype (and, for Livox, the companion fields `tag`/`line`):
//
// * `t` uint32: ns since the message stamp; stamp = scan start. Ouster's ouster_ros driver
//   (point type with `uint32_t t`; the message is stamped with the first column's time).
// * `offset_time` uint32: ns since the message stamp; stamp = scan start. Livox's CustomPoint.msg
//   ("offset time relative to the base time"; base time = header stamp = first point).
// * `time` float32: s since the message stamp; stamp = scan END. Velodyne's ros-drivers/velodyne
//   PointXYZIRT (the driver stamps a scan with its last packet, so the times are mostly <= 0).
// * `timestamp` float64 together with `tag` and `line`: ABSOLUTE ns; stamp = scan start. Livox
//   ROS driver 2, PointCloud2 output (xfer_format 0, LivoxPointXyzrtlt: `double timestamp` is the
//   packet's base time plus the point's offset, in ns; header stamp = base time).
// * `timestamp` float64 otherwise: ABSOLUTE s. Hesai's HesaiLidar_ROS_2.0 (stamp = scan start) and
//   Robosense's rslidar_sdk (stamp = last point unless `ts_first_point`) PointXYZIRT.
//
// Integer `t`/`offset_time` of any integer width and `time` as float64 are accepted with the same
// meaning. "stamp at" matters only where the points carry no time (azimuth recovery below) and is
// documented per driver; everything is overridable (TimeFieldOptions). A field that looks like a
// time (one of the names above) with another datatype is an error naming every field found, never
// a silent guess; a layout with no time field at all gets its times from the azimuth (logged once).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {

// Datatype codes of sensor_msgs/PointField and pcl::PCLPointField (identical numbering).
enum FieldDatatype : uint8_t {
  kInt8 = 1,
  kUInt8 = 2,
  kInt16 = 3,
  kUInt16 = 4,
  kInt32 = 5,
  kUInt32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};
size_t FieldDatatypeSize(uint8_t datatype);       // 0 for an unknown code
std::string FieldDatatypeName(uint8_t datatype);  // "float32", ..., "type 9"

struct PointField {
  std::string name;
  uint8_t datatype = kFloat32;
  uint32_t offset = 0;
  uint32_t count = 1;
};
// "x:float32 y:float32 z:float32 t:uint32" — the field list as error messages show it.
std::string DescribeFields(const std::vector<PointField>& fields);

enum class TimeUnit { kSeconds, kMilliseconds, kMicroseconds, kNanoseconds };
enum class TimeReference { kRelativeToStamp, kAbsolute };
enum class StampAt { kScanStart, kScanEnd };

// How the per-point time of a layout is read (the matched convention or the override).
struct TimeConvention {
  std::string field;  // empty: the layout has no time field
  TimeUnit unit = TimeUnit::kNanoseconds;
  TimeReference reference = TimeReference::kRelativeToStamp;
  StampAt stamp_at = StampAt::kScanStart;
  std::string driver;  // the convention's name for logs ("Ouster", "override", ...)
};

// User overrides; every part left unset is detected. `field = "none"` ignores any time field.
struct TimeFieldOptions {
  std::string field;
  std::optional<TimeUnit> unit;
  std::optional<TimeReference> reference;
  std::optional<StampAt> stamp_at;
  int64_t scan_period_ns = 100'000'000;  // for azimuth recovery (10 Hz)
};
// Parsers for command-line values: "s|ms|us|ns", "relative|absolute", "start|end". Throw
// std::invalid_argument naming the accepted values.
TimeUnit ParseTimeUnit(const std::string& s);
TimeReference ParseTimeReference(const std::string& s);
StampAt ParseStampAt(const std::string& s);
std::string DescribeConvention(const TimeConvention& c);  // "t (uint32 ns since stamp, Ouster)"

struct PointLayout {
  uint32_t point_step = 0;
  PointField x, y, z;
  std::optional<PointField> time, intensity, ring;
  TimeConvention convention;
};

// Checks the layout and matches the time convention. Errors (std::runtime_error, prefixed by
// `where`, listing the fields found): no x/y/z, x/y/z not float32/float64, a count other than 1,
// a field past point_step, a time-like field of the wrong datatype, an override naming a field
// that is absent. `point_step` = 0 skips the bounds check (PCL computes it itself).
PointLayout DetectPointLayout(const std::vector<PointField>& fields, uint32_t point_step,
                              const TimeFieldOptions& options, const std::string& where);

// The absolute time [ns] of the point stored at `p`; false if the stored value is not finite or
// the time does not fit int64 nanoseconds.
bool PointTimeNs(const PointLayout& layout, const uint8_t* p, int64_t stamp_ns, int64_t* t_ns);

// Appends `n` points stored `point_step` bytes apart (little-endian) to `out`: x/y/z, intensity,
// ring and, when the layout has a time field, absolute times. Non-finite points are dropped and
// counted; a time that is not one (PointTimeNs) is an error naming `where` and the point index.
void DecodePoints(const uint8_t* data, size_t n, const PointLayout& layout, int64_t stamp_ns,
                  const std::string& where, PointCloud* out);

// The inverse of DecodePoints, for writers and tests: `cloud.size()` points of `point_step` bytes
// laid out as `fields` (zero where the cloud has no value), the time stored by `convention`
// relative to `cloud.stamp_ns` or absolute. Throws if a value does not fit its field (a negative
// time in an unsigned field, more than 4.29 s in uint32 ns).
std::vector<uint8_t> EncodePoints(const PointCloud& cloud, const std::vector<PointField>& fields,
                                  uint32_t point_step, const TimeConvention& convention);
// The Ouster layout of the Newer College Dataset (PCD files and os1_cloud_node/points):
// x y z intensity float32, t uint32, reflectivity uint16, ring uint8, noise uint16, range uint32.
std::vector<PointField> OusterFields(uint32_t* point_step);

// Reads a scalar of any FieldDatatype as double (unaligned memory allowed); NaN for unknown codes.
double ReadFieldValue(const uint8_t* p, uint8_t datatype);

// Azimuth recovery for clouds without per-point times: a spinning lidar (clockwise seen from
// above, as Velodyne, Ouster and the KITTI HDL-64E) fires at azimuth a at
//   t(a) = t(a₀) + wrap₂π(a₀ − a) / 2π · period,
// a₀ being the azimuth at which the sweep begins. Returns the offset [ns] in [0, period).
int64_t AzimuthOffsetNs(const Vec3& p, double start_azimuth, int64_t period_ns);

// Fills cloud->times_ns from the azimuth, the sweep beginning at the first point's azimuth:
// times = stamp + offset (stamp at scan start) or stamp − period + offset (stamp at scan end).
void FillTimesFromAzimuth(PointCloud* cloud, StampAt stamp_at, int64_t period_ns);

}  // namespace ctlio::io
