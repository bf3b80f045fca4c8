#include "ctlio/solvers/lio/scan_preparation.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/solvers/lio/input_checks.h"

namespace ctlio::lio {

namespace {

// Time order groups the points of one firing, whose interpolated pose the pipelines share. A
// sweep usually arrives in firing order already: then the (allocating) sort is skipped.
void SortByTime(std::vector<TimedPoint>* points) {
  const auto by_time = [](const TimedPoint& a, const TimedPoint& b) { return a.time < b.time; };
  if (!std::is_sorted(points->begin(), points->end(), by_time)) {
    std::stable_sort(points->begin(), points->end(), by_time);
  }
}

}  // namespace

void CheckScan(const LidarScan& scan, const int64_t* previous_end_ns) {
  if (scan.points.size() != scan.times_ns.size()) {
    throw std::invalid_argument("LioOdometry::AddScan: scan ending at " +
                                std::to_string(scan.end_ns) + " ns has " +
                                std::to_string(scan.points.size()) + " points but " +
                                std::to_string(scan.times_ns.size()) + " times");
  }
  if (scan.end_ns <= scan.begin_ns) {
    throw std::invalid_argument("LioOdometry::AddScan: scan end " + std::to_string(scan.end_ns) +
                                " ns is not after its begin " + std::to_string(scan.begin_ns));
  }
  if (previous_end_ns != nullptr && scan.end_ns <= *previous_end_ns) {
    throw std::invalid_argument(
        "LioOdometry::AddScan: scan ending at " + std::to_string(scan.end_ns) +
        " ns is not after the previous one (" + std::to_string(*previous_end_ns) + " ns)");
  }
}

const LidarScan& DropPointsOutsideInterval(const LidarScan& scan, int64_t interval_begin_ns,
                                           double tolerance_s, LidarScan* trimmed,
                                           std::string* note) {
  const int64_t tolerance = std::llround(tolerance_s * 1e9);
  const int64_t begin = interval_begin_ns;
  // Saturating: a window wrapped around the int64 limits was inverted and dropped the whole scan.
  const int64_t lo = SaturatingSubNs(begin, tolerance),
                hi = SaturatingAddNs(scan.end_ns, tolerance);
  const auto outside = [&](int64_t t) { return t < lo || t > hi; };
  if (std::none_of(scan.times_ns.begin(), scan.times_ns.end(), outside)) return scan;
  *trimmed = scan;
  const size_t dropped = DropPointsOutside(lo, hi, trimmed);
  std::ostringstream m;
  m << std::fixed << std::setprecision(9) << "dropped " << dropped << " of " << scan.points.size()
    << " points timed outside [" << 1e-9 * double(begin) << ", " << 1e-9 * double(scan.end_ns)
    << "] s by more than input.scan_time_tolerance " << tolerance_s << " s";
  *note = m.str();
  return *trimmed;
}

void PrepareScan(const LidarScan& scan, const SE3& T_robot_lidar, int64_t interval_begin_ns,
                 const ImuBuffer& clock, int threads, LidarFrontend* frontend,
                 PreparedScan* prepared) {
  const double t_prev = clock.Seconds(interval_begin_ns);
  prepared->t_begin = clock.Seconds(scan.begin_ns);
  prepared->t_end = clock.Seconds(scan.end_ns);
  prepared->end_ns = scan.end_ns;
  // The configured extrinsic, or with online calibration its current estimate (the lidar
  // residuals recover the lidar-frame points through prepared->T_robot_lidar).
  prepared->T_robot_lidar = T_robot_lidar;
  // Range gate and voxel subsampling in the lidar frame (one pass, no copy of the up to 230 000
  // raw returns of a 128-beam sweep), then on the survivors in the robot frame, and the
  // keypoints: one stream, no intermediate copies (LidarFrontend::SelectSweep).
  thread_local SweepSelection selection;
  frontend->SelectSweep(scan.points, prepared->T_robot_lidar, &selection, threads);
  prepared->points.resize(selection.indices.size());
  for (size_t j = 0; j < selection.indices.size(); ++j) {
    TimedPoint& p = prepared->points[j];
    p.point = selection.points_robot[j];
    // Points are registered between the previous knot and this one; a time outside by less than
    // input.scan_time_tolerance (clock jitter of the driver; the rest was dropped and counted in
    // DropPointsOutsideInterval) is clamped onto the interval rather than extrapolated. Finite,
    // so Preprocess's time check (RangeGate) would keep every point.
    p.time =
        std::clamp(clock.Seconds(scan.times_ns[selection.indices[j]]), t_prev, prepared->t_end);
  }
  prepared->keypoints.clear();
  prepared->keypoints.reserve(selection.keypoints.size());
  for (const size_t j : selection.keypoints) prepared->keypoints.push_back(prepared->points[j]);
  SortByTime(&prepared->points);
  SortByTime(&prepared->keypoints);
}

}  // namespace ctlio::lio
