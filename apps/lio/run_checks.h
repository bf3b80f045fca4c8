// Checks of a whole run that no single scan can make (docs/user-guide/bad-input.md):
//  - an unusable run: no scan after the first was registered by the lidar, so the "estimate" is
//    the motion prior's guess (lidar_only: identity, frozen) and an ATE of it would look
//    plausible while meaning nothing;
//  - lidar gaps: scans missing from the recording (a spacing of the scan ends above 3× the median
//    spacing), which no per-scan status shows.
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

// Lidar gaps among consecutive scan end times (increasing): a spacing above `factor` × the median
// spacing. Needs 3 scans (2 spacings) for a median.
struct LidarGaps {
  int count = 0;
  double median_period_s = 0.0;
  double longest_s = 0.0;
  std::string first;  // "gap of 1.000 s between the scans ending at … s and … s (median …)"
};
LidarGaps FindLidarGaps(const std::vector<int64_t>& scan_ends_ns, double factor = 3.0);

}  // namespace ctlio::lioapp
