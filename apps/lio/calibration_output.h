// Output of the odometry's online lidar–IMU calibration (OdometryConfig::calibration): the
// per-scan log calibration.csv (estimates and marginal σ over time, read by
// tools/plot_calibration.py) and calibration.yaml, the final values as a `calibration:` (and
// `imus:`) snippet to paste into an odometry config. Shared by ctlio_odometry and ctlio_experiment.
#pragma once

#include <cmath>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/calibration_options.h"
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

// One calibration coordinate of what a run recommends writing: its estimate, σ and start, the
// value written and why. Units: δ in s; the extrinsic's ρ in m and φ in rad, as the left-tangent
// components of Log(T·T_start⁻¹) (calibration.csv's coordinates), so its start is 0.
struct CoordinateChoice {
  std::string name;          // CalibrationCoordinates
  double estimate = 0.0;     // the last estimate
  double sigma = 0.0;        // its marginal σ (NaN: none reported)
  double start = 0.0;        // the value the run started from
  double threshold = 0.0;    // calibration.write_max_sigma_* of its kind, same unit
  double prior_sigma = 0.0;  // the prior σ the calibration state started with, same unit
  bool estimate_written = false;
  double written = 0.0;                 // estimate or start
  std::string reason;                   // why that one, for a person
  double unobservable_fraction = -1.0;  // of the assessed scans (< 0: not assessed); information
  // |last − middle| estimate over the second half of the run's scans, in units of σ (NaN: none).
  double drift_sigmas = NAN;
};

// The calibration a run recommends using in a config, per coordinate (CalibrationOptions):
//  0. the start where the estimate moved by more than write_max_drift_sigmas × σ over the
//     second half of the run (a drift its σ does not show: the slow regime's δ, 11 ms off with
//     σ 0.44 ms, docs/experiments/calibration.md);
//  1. the last estimate where its marginal σ is below the threshold of its kind
//     (options.write_max_sigma_s, _deg, _m), whatever share of scans the observability check
//     flagged (issue 45: an offset estimated 20.045 ± 0.20 ms, flagged on 81% of the scans, is
//     a calibration);
//  2. else the estimate where the data informed it: σ ≤ write_max_sigma_ratio × the prior σ and
//     the check flagged it after at most write_max_unobservable_fraction of the assessed scans
//     (not assessed: σ alone);
//  3. else the value the run started from (δ_j: run.initial_time_offsets; the extrinsic's ρ / φ
//     set to zero): σ near the prior's, or a small σ the check contradicts (the slow regime's
//     drift, whose window σ counts the marginal prior again each slide).
// `keep_uninformed_at_start` false writes every estimate. Nothing without an estimate.
struct RecommendedCalibration {
  std::vector<double> time_offset_s;  // per IMU [s]
  bool has_extrinsic = false;
  SE3 T_imu_lidar;
  Vec6 extrinsic_from_start = Vec6::Zero();   // [ρ; φ] of T_imu_lidar from the start, kept axes 0
  std::vector<std::string> kept_at_start;     // coordinate names (CalibrationCoordinates)
  std::vector<CoordinateChoice> coordinates;  // every coordinate, in CalibrationCoordinates order
};
std::optional<RecommendedCalibration> RecommendCalibration(const RunSummary& run,
                                                           const lio::CalibrationOptions& options,
                                                           bool keep_uninformed_at_start = true);

// Run summary lines (evaluation.txt): calibration_unobservable_final (the coordinates
// unobservable after the last scan, or -), calibration_information_final (ν per coordinate),
// calibration_unobservable_fraction (per coordinate, of the assessed scans), with the
// observability check only; calibration_kept_at_start (`recommended`'s, or -) with a calibration.
void WriteObservabilitySummary(const RunSummary& run,
                               const std::optional<RecommendedCalibration>& recommended,
                               std::ostream& out);

// `recommended` (RecommendCalibration of `run`) as calibration.yaml: a header saying how to use
// it and the rule, then per coordinate one comment block read top-down — estimate, σ, start,
// written value and why (and, where the source knows it, the truth; with the observability
// check, the share of scans it flagged) — then the keys: `calibration: {time_offset_s}` and,
// with the extrinsic estimated, an `extrinsic:` section (rotation, translation), so that the file
// is also an overlay (--config my.yaml,calibration.yaml). False (nothing written) without an
// estimate.
bool WriteCalibrationYaml(const std::string& path, const RunSummary& run,
                          const RecommendedCalibration& recommended);

}  // namespace ctlio::lioapp
