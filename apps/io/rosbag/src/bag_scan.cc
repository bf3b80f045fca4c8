// BagSource: one sensor_msgs/PointCloud2 into a ScanFrame with absolute per-point times: the
// time field or the azimuth, the per-point time rules of the folder readers (point_time_check.h),
// the recovery of unusable scans, the order of scans.
#include <glog/logging.h>

#include <algorithm>
#include <stdexcept>

#include "bag_source_impl.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/pointcloud2.h"

namespace ctlio::io {

void BagSource::Impl::AddScan(const sensor_msgs::PointCloud2& m) {
  const std::string where = Where(lidar_topic, lidar_messages);
  ScanFrame f;
  PointLayout layout;
  f.cloud = DecodePointCloud2(m, options.time, where, &layout);
  if (!layout.time) {
    if (!azimuth_logged) {
      LOG(INFO) << path << ": " << lidar_topic
                << " has no per-point time field (fields: " << DescribeFields(FieldsOf(m))
                << "): times recovered from the azimuth, stamp at "
                << "scan " << (layout.convention.stamp_at == StampAt::kScanStart ? "start" : "end");
      azimuth_logged = true;
    }
    FillTimesFromAzimuth(&f.cloud, layout.convention.stamp_at, options.time.scan_period_ns);
  } else if (lidar_messages == 1) {
    LOG(INFO) << path << ": per-point time " << DescribeConvention(layout.convention);
  }
  const int64_t stamp = f.cloud.stamp_ns;
  if (last_lidar_stamp_ns != INT64_MIN && stamp > last_lidar_stamp_ns) {
    last_lidar_spacing_ns = stamp - last_lidar_stamp_ns;  // no overflow: both are ≥ 0 (ros::Time)
  }
  last_lidar_stamp_ns = stamp;
  if (layout.time) {
    // The same per-point time rules as the folder readers (point_time_check.h, dataset.h). Before
    // the second stamp the period is unknown: twice the nominal one keeps a 5 Hz lidar's sweep.
    const int64_t period = last_lidar_spacing_ns > 0
                               ? last_lidar_spacing_ns
                               : 2 * std::max<int64_t>(options.time.scan_period_ns, 1);
    const PointTimeCheck check = CheckPointTimes(&f.cloud, period);
    if (check.verdict != PointTimeCheck::kSweep) {
      ++retimed_scans;
      const bool azimuth = check.verdict == PointTimeCheck::kNotASweep;
      if (warnings->Count(azimuth ? "per-point times not a sweep" : "per-point times rescaled",
                          where + check.reason)) {
        // An integer field of 8 or 16 bits cannot hold a sweep in ns (it wraps every 256 ns or
        // 65.5 µs): the width is the likely cause, said with the field's type.
        const size_t bytes = FieldDatatypeSize(layout.time->datatype);
        const std::string narrow =
            azimuth && bytes <= 2 && layout.time->datatype != kFloat32 &&
                    layout.time->datatype != kFloat64
                ? " (a " + FieldDatatypeName(layout.time->datatype) + " field holds at most " +
                      std::to_string((1u << (8 * bytes - (layout.time->datatype == kInt8 ||
                                                          layout.time->datatype == kInt16))) -
                                     1) +
                      " units: too narrow for a sweep)"
                : "";
        LOG(WARNING) << where << "time field " << DescribeConvention(layout.convention) << narrow
                     << ": " << check.reason
                     << (azimuth ? "; times recovered from the azimuth instead" : "");
      }
      if (azimuth) {
        FillTimesFromAzimuth(
            &f.cloud, layout.convention.stamp_at,
            last_lidar_spacing_ns > 0 ? last_lidar_spacing_ns : options.time.scan_period_ns);
      }
    }
    // A point timed more than a period (+10 %) from the stamp cannot belong to this sweep (either
    // stamp position, scan start or end); it would stretch the scan over seconds. Dropped and
    // counted, as in the folder readers.
    const int64_t reach = period + period / 10;
    int64_t lo = INT64_MIN, hi = INT64_MAX;
    if (__builtin_sub_overflow(stamp, reach, &lo)) lo = INT64_MIN;
    if (__builtin_add_overflow(stamp, reach, &hi)) hi = INT64_MAX;
    points_outside_sweep +=
        DropPointsOutside(where.substr(0, where.size() - 2), lo, hi, &f.cloud, warnings.get());
  }
  // A stamp at the scan start is the start (DataSource: start_ns = the scan stamp) even when the
  // first returns were dropped; otherwise the earliest point is.
  f.start_ns = f.end_ns = stamp;
  if (f.cloud.has_times() && !f.cloud.points.empty()) {
    const auto [lo, hi] = std::minmax_element(f.cloud.times_ns.begin(), f.cloud.times_ns.end());
    f.start_ns = layout.convention.stamp_at == StampAt::kScanStart ? std::min(stamp, *lo) : *lo;
    f.end_ns = *hi;
  }
  if (f.end_ns <= f.start_ns) {
    // Recovery, as in the folder readers (README "Bad input"): a cloud without usable points
    // (empty, all non-finite) or with every point at one instant gives no interval; it is handed on
    // with its nominal one (one scan period from the stamp, or up to it for a stamp at the scan
    // end; the period is the last stamp spacing, so that the interval ends before the next scan,
    // else scan_period_ns) and the odometry reports it degenerate when it has no points.
    const int64_t period = std::max<int64_t>(
        last_lidar_spacing_ns > 0 ? last_lidar_spacing_ns : options.time.scan_period_ns, 2);
    const bool at_end = layout.convention.stamp_at == StampAt::kScanEnd;
    int64_t lo = stamp, hi = stamp;
    const bool overflow = at_end ? __builtin_sub_overflow(stamp, period - 1, &lo)
                                 : __builtin_add_overflow(stamp, period - 1, &hi);
    if (overflow) {
      throw std::runtime_error(where + "stamp " + std::to_string(stamp) +
                               " ns leaves no room for a scan period");
    }
    ++unusable_scans;
    if (warnings->Count("unusable scan",
                        where + std::to_string(f.cloud.size()) + " usable points")) {
      LOG(WARNING) << where << f.cloud.size() << " usable points (" << f.cloud.dropped_non_finite
                   << " non-finite), " << (f.cloud.points.empty() ? "none" : "all at one instant")
                   << ": handed on with its nominal interval [" << FormatSecondsNs(lo) << ", "
                   << FormatSecondsNs(hi) << "] s (unusable scan " << unusable_scans << ")";
    }
    f.start_ns = lo;
    f.end_ns = hi;
  }
  f.cloud.stamp_ns = f.start_ns;
  if (f.start_ns < last_scan_start_ns) {
    throw std::runtime_error(where + "scan starts before the previous one (scans out of order)");
  }
  last_scan_start_ns = f.start_ns;
  pending.push_back(std::move(f));
}

}  // namespace ctlio::io
