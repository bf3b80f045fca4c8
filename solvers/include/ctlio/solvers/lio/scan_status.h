// The ways a registered scan is not `ok`, each with the one message a user reads for it
// (ScanResult::status and ::message; docs/user-guide/outputs.md lists the statuses). LioOdometry
// decides when they apply; the wording lives here so that it exists once.
#pragma once

#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// The newest pose moved `jump` m in one scan, above `limit` (init.max_scan_translation), or is not
// finite: the scan failed and its points stay out of the map. Returns false in that case.
bool CheckPlausibleJump(double jump, bool finite, double limit, ScanResult* result);

// Fewer than `min_associations` plane associations: the lidar term was dropped, the prior (and
// the IMU, `uses_imu`) carry the state. Leaves a scan that is already not `ok` as it is.
void MarkTooFewAssociations(int min_associations, bool uses_imu, ScanResult* result);

// A scan no IMU measures (lidar_only) with degenerate lidar directions (result->degeneracy):
// which ones, and whether the prediction was kept along them (solution remapping). Leaves a scan
// that is already not `ok` as it is.
void MarkDegenerateDirections(ScanResult* result);

}  // namespace ctlio::lio
