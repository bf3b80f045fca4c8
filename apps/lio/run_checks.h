// Checks of a whole run that no single scan can make (docs/user-guide/bad-input.md):
//  - an unusable run: no scan after the first was registered by the lidar, so the "estimate" is
//    the motion prior's guess (lidar_only: identity, frozen) and an ATE of it would look
//    plausible while meaning nothing;
//  - lidar gaps: scans missing from the recording (a spacing of the scan ends above 3× the median
//    spacing), which no per-scan status shows.
//  - IMU–lidar inconsistency: the IMU terms cannot agree with the motion the lidar fixed (the
//    median whitened χ²/dof of the accelerometer terms over the moving scans far above 1): a
//    sign-flipped accelerometer passes the gravity check (it reads like an upside-down IMU at
//    rest) and gave 0.14 m of error with every scan `ok`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lioapp {

// Empty when at least one scan after the first (which only starts the map) has status `ok` or
// `imu_gap`: the lidar fixed that pose against the map. Else why not, with the statuses counted,
// e.g. "no scan after the first was registered by the lidar (29 degenerate, 0 failed, 0 suspect
// of 30 scans)". `suspect` scans do not count: the frozen-IMU gate already fails those runs, and
// their pose is not one the lidar fixed alone. A run of fewer than 2 scans is not judged here
// (RunOdometry fails it for its missing trajectory).
std::string UnregisteredRunReason(const std::vector<lio::ScanResult>& scans);

// A run in which the lidar fixed only part of the poses: more than `max_fraction` of the scans
// after the first (and at least 3) have status `degenerate`, so there the trajectory is the
// motion prior's and the IMU's dead reckoning. Empty otherwise (and for an unregistered run,
// which UnregisteredRunReason reports). A voxel size near the lidar's range (every second scan
// degenerate, 5x the clean ATE, exit 0 with no warning) is the case that asked for it; a
// featureless scene gives the same count and deserves the same warning.
std::string DegenerateRunWarning(const std::vector<lio::ScanResult>& scans,
                                 double max_fraction = 0.1);

// Lidar gaps among consecutive scan end times (increasing): a spacing above `factor` × the median
// spacing. Needs 3 scans (2 spacings) for a median.
struct LidarGaps {
  int count = 0;
  double median_period_s = 0.0;
  double longest_s = 0.0;
  std::string first;  // "gap of 1.000 s between the scans ending at … s and … s (median …)"
};
LidarGaps FindLidarGaps(const std::vector<int64_t>& scan_ends_ns, double factor = 3.0);

// IMU–lidar consistency from the scans' IMU χ² (ScanResult::accel_chi2 …, imu_consistency.h).
// Judged over the moving scans: status `ok` (the lidar fixed the pose), the pose moved against the
// previous scan's by more than input.moving_translation / moving_rotation, and IMU terms present;
// a still platform cannot show a wrong accelerometer (gravity alone passes the gravity check).
struct ImuConsistencyOptions {
  // Thresholds on the median χ²/dof, set by measurement (docs/user-guide/bad-input.md, "IMU–lidar
  // consistency"), not by the nominal 1: Singer-LIO's clean simulated runs gave 0.003–0.17, but
  // 15–18 in the fast regime (interpolation error beyond the configured noise); a flipped
  // accelerometer 0.006–62 000, above 30 only where the lidar wins over it.
  double max_accel = 30.0;
  double max_gyro = 30.0;
  int min_scans = 10;  // fewer moving scans are not judged
};
// The IMU-as-input baseline is not judged (its medians are still reported): its preintegrated
// factor's χ²/dof did not separate (clean 0.003–1.6, flipped 0.003–1.3).
struct ImuConsistency {
  int moving_scans = 0;       // scans judged
  double median_accel = 0.0;  // median χ²/dof of the accelerometer terms (0: none)
  double median_gyro = 0.0;   // of the gyro terms
  std::string warning;        // empty when consistent or not judged
};
ImuConsistency CheckImuConsistency(const std::vector<lio::ScanResult>& scans,
                                   const lio::OdometryConfig& config,
                                   const ImuConsistencyOptions& options = {});

}  // namespace ctlio::lioapp
