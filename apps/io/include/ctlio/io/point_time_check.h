// The one check of a scan's per-point times, shared by every reader (bag PointCloud2, Newer
// College PCD folders, KITTI), so that times that cannot be a sweep get the same answer in every
// layout. A field's name and datatype (point_fields.h) say what its values should mean, not what
// they are: a driver that writes microseconds where nanoseconds are expected, an 8/16-bit field
// that cannot hold a 0.1 s sweep in ns, a `t` that is really `ring` or `range`, or a cloud with
// every point at one instant all decode without an error and used to be deskewed with times that
// are not a sweep. The spread of the times is what tells: a sweep of a lidar with scan period P
// spans about P (a cropped field of view less, never under 1 %; never more than 1.5 P).
//
// The spread is the 5–95 % quantile range, so that a few points timed seconds outside the sweep
// (CheckPointTimes leaves those to DropPointsOutside, dataset.h) do not make a good sweep look
// too long. Verdicts:
//   * a sweep: spread in [P/100, 1.5 P] and the median within 2 P of the stamp;
//   * rescaled: a unit factor (10³, 10⁶, 10⁻³, 10⁻⁶) brings the spread into [0.2 P, 1.5 P] and the
//     median within 2 P of the stamp, and the points in time order follow the scan pattern (the
//     azimuth of consecutive points changes by under 0.3 rad in the median: a sweep moves on
//     continuously, ring numbers or ranges jump around). The times are rescaled about the stamp;
//   * not a sweep: anything else, including every point at one instant. The caller replaces the
//     times by its azimuth times (as for a cloud without a time field) and warns with `reason`.
// With fewer than kMinPointsForSpread points only "every point at one instant" is judged: a
// handful of points (a test cloud, a tiny crop) says nothing about the period.
#pragma once

#include <cstdint>
#include <string>

#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {

constexpr size_t kMinPointsForSpread = 100;

struct PointTimeCheck {
  enum Verdict { kSweep, kRescaled, kNotASweep };
  Verdict verdict = kSweep;
  double factor = 1.0;  // the unit factor applied (kRescaled)
  // Why (kRescaled, kNotASweep), for the reader's warning: "per-point times span 0.000099 s, not a
  // sweep of 0.1 s; read with a unit factor 1000 (microseconds where nanoseconds are expected?)".
  std::string reason;
};

// Judges the times of `cloud` (absolute, about cloud->stamp_ns) against the scan period
// `period_ns` (> 0). Rescales them in place for kRescaled; leaves them for kNotASweep. A cloud
// without times or with fewer than two points is a sweep (nothing to judge).
PointTimeCheck CheckPointTimes(PointCloud* cloud, int64_t period_ns);

}  // namespace ctlio::io
