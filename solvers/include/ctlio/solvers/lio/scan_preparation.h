// The input side of a scan in LioOdometry (lio_odometry.h), before any state is touched: the
// checks that throw (arrays, order), the input gate on point times (input_checks.h) and the
// preparation for the estimators (PreparedScan: robot frame, range gate, voxel subsampling,
// keypoints, odometry seconds, time order).
#pragma once

#include <cstdint>
#include <string>

#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/imu_buffer.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// Throws std::invalid_argument (naming LioOdometry::AddScan) for a scan whose point and time
// arrays differ in length, whose end is not after its begin, or, with `previous_end_ns` (the
// previous scan's end; nullptr before the first scan), which does not end after the previous one.
void CheckScan(const LidarScan& scan, const int64_t* previous_end_ns);

// Input gate: the points timed outside [interval_begin_ns − tolerance, end + tolerance]
// (tolerance_s: input.scan_time_tolerance; the interval starts at the previous scan's end once
// initialised, at the scan's own begin before) are dropped into *trimmed, which is returned with
// *note saying so; `scan` itself (and *note untouched) when none is.
const LidarScan& DropPointsOutsideInterval(const LidarScan& scan, int64_t interval_begin_ns,
                                           double tolerance_s, LidarScan* trimmed,
                                           std::string* note);

// Robot-frame points (T_robot_lidar: the extrinsic or its estimate), range gate, voxel
// subsampling, keypoints (frontend->SelectSweep with `threads`), times in `clock`'s odometry
// seconds, time order. Times within the tolerance outside the interval (driver clock jitter) are
// clamped onto [interval_begin_ns, scan end]. Into *prepared, whose buffers' capacity is reused:
// fresh megabyte vectors per scan were page faults in every scan.
void PrepareScan(const LidarScan& scan, const SE3& T_robot_lidar, int64_t interval_begin_ns,
                 const ImuBuffer& clock, int threads, LidarFrontend* frontend,
                 PreparedScan* prepared);

}  // namespace ctlio::lio
