// Output of the odometry's online lidar–IMU calibration (OdometryConfig::calibration): the
// per-scan log calibration.csv (estimates and marginal σ over time, read by
// tools/plot_calibration.py) and calibration.yaml, the final values as a `calibration:` (and
// `imus:`) snippet to paste into an odometry config. Shared by ctlio_odometry and ctlio_experiment.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lio/run_odometry.h"

namespace ctlio::lioapp {

// The last scan that reports a calibration estimate (nullptr: none).
const lio::ScanResult* LastCalibration(const RunSummary& run);

// CSV, one row per scan with an estimate: t_s, then per IMU j time_offset_j_s,
// time_offset_j_sigma_s (NaN σ: not computed), then the extrinsic's columns when estimated.
// The write is checked (an error names the path).
void WriteCalibrationLog(const std::string& path, const RunSummary& run);

// The final estimates (and σ, and the truth where the source knows it) as YAML comments around a
// `calibration:` mapping with time_offset_s; false (nothing written) without an estimate.
bool WriteCalibrationYaml(const std::string& path, const RunSummary& run);

}  // namespace ctlio::lioapp
