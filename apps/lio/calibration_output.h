// Output of the odometry's online lidar–IMU calibration (OdometryConfig::calibration): the
// per-scan log calibration.csv (estimates and marginal σ over time, read by
// tools/plot_calibration.py) and calibration.yaml, the final values as a `calibration:` (and
// `imus:`) snippet to paste into an odometry config. Shared by ctlio_odometry and ctlio_experiment.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lio/run_odometry.h"

namespace ctlio::lioapp {

// The last scan that reports a calibration estimate (nullptr: none).
const lio::ScanResult* LastCalibration(const RunSummary& run);

// Names of the calibration coordinates of an estimate, in the order of its observability:
// time_offset_<j> per IMU, then extrinsic_rho_<x|y|z>, extrinsic_phi_<x|y|z>.
std::vector<std::string> CalibrationCoordinates(const lio::ScanResult::CalibrationEstimate& c);
// Coordinate i's observability after a scan as two CSV fields, "ν,observable|unobservable", or
// "nan,-" where it was not assessed (the initialising scan, the check off).
void WriteCoordinateObservability(const lio::ScanResult::CalibrationEstimate& c, size_t i,
                                  std::ostream& out);
// Whether any scan carries the observability of the calibration (calibration_observability.h).
bool HasObservability(const RunSummary& run);
// Per calibration coordinate (as ScanResult::CalibrationEstimate::observability): the fraction
// of the assessed scans after which it was unobservable (empty: never assessed).
std::vector<double> UnobservableFraction(const RunSummary& run);

// CSV, one row per scan with an estimate: t_s, then per IMU j time_offset_j_s,
// time_offset_j_sigma_s (NaN σ: not computed), then the extrinsic's columns when estimated, then
// with the observability check per coordinate <name>_information (ν) and <name>_status
// (observable | unobservable), then, when any scan held a coordinate (warm-up replay's held pass,
// hold_unobservable), per coordinate <name>_held (1: held at its value in that scan's solve).
// The write is checked (an error names the path). `scans`: run.scans by default; after a warm-up
// replay also run.warmup_live_scans (the estimates returned live before it), same columns.
void WriteCalibrationLog(const std::string& path, const RunSummary& run,
                         const std::vector<lio::ScanResult>* scans = nullptr);

// A coordinate unobservable after more than this fraction of the assessed scans was never
// calibrated by the run: its estimate is wherever the trajectory's errors pushed it (slow regime:
// tens of degrees and centimetres from both the start and the truth, docs/experiments/
// calibration.md), so the values recommended for a config keep the start along it.
inline constexpr double kKeepAtStartUnobservableFraction = 0.5;

// The calibration a run recommends pasting into a config: the last estimate, except that with
// `keep_unobservable_at_start` every coordinate unobservable after more than
// kKeepAtStartUnobservableFraction of the assessed scans keeps the value the run started from
// (δ_j: run.initial_time_offsets; the extrinsic's ρ / φ: the left-tangent components of
// Log(T·T_start⁻¹) set to zero, as calibration.csv's coordinates). Nothing without an estimate.
struct RecommendedCalibration {
  std::vector<double> time_offset_s;  // per IMU [s]
  bool has_extrinsic = false;
  SE3 T_imu_lidar;
  Vec6 extrinsic_from_start = Vec6::Zero();  // [ρ; φ] of T_imu_lidar from the start, kept axes 0
  std::vector<std::string> kept_at_start;    // coordinate names (CalibrationCoordinates)
};
std::optional<RecommendedCalibration> RecommendCalibration(const RunSummary& run,
                                                           bool keep_unobservable_at_start = true);

// Run summary lines (evaluation.txt): calibration_unobservable_final (the coordinates
// unobservable after the last scan, or -), calibration_information_final (ν per coordinate),
// calibration_unobservable_fraction (per coordinate, of the assessed scans) and
// calibration_kept_at_start (`recommended`'s, or -). Nothing without the observability check.
void WriteObservabilitySummary(const RunSummary& run,
                               const std::optional<RecommendedCalibration>& recommended,
                               std::ostream& out);

// `recommended` (RecommendCalibration of `run`; and the last estimate, σ and the truth where the
// source knows it, as comments) as a `calibration:` mapping with time_offset_s and, with the
// extrinsic estimated, an `extrinsic:` section; a comment names every coordinate kept at its
// start. False (nothing written) without an estimate.
bool WriteCalibrationYaml(const std::string& path, const RunSummary& run,
                          const RecommendedCalibration& recommended);

}  // namespace ctlio::lioapp
