// The experiment's per-run results and the table pooled from them (SPEC §6). One results.csv per
// experiment job holds one line per (regime, sequence, method, scenario) run; settings.txt holds
// the simulation settings that must be equal for runs to be pooled. The table is computed from
// the lines alone, so the lines of many split jobs merged give the table of one job over all
// their runs.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ctlio::lioapp {

struct RunRow {
  std::string regime;
  int sequence = 0;
  std::string method;
  std::string scenario = "none";  // "none" or an IMU outage, e.g. "outage_1s"
  double ate_rmse_m = 0.0;        // NaN when the run has no ATE
  size_t ate_pairs = 0;
  int failed_scans = 0, degenerate_scans = 0, imu_gap_scans = 0;
  bool failure = false;
  double median_ms = 0.0, p95_ms = 0.0, max_ms = 0.0, median_cpu_ms = 0.0, p95_cpu_ms = 0.0;
  // RunSummary::drift_per_100m (NaN without one), the scans run and those with a degenerate
  // direction of the lidar term (lio/degeneracy.h).
  double drift_m_per_100m = 0.0;
  int scans = 0, degenerate_direction_scans = 0;
  std::string error;
};

// Writes the rows with full precision (the pooled RMSE of merged files then equals a single
// job's to the last digit of the table).
void WriteResultsCsv(const std::string& path, const std::vector<RunRow>& rows);
// Reads a file written by WriteResultsCsv; throws naming file and line on malformed input.
std::vector<RunRow> ReadResultsCsv(const std::string& path);

// One cell of the table: the runs of a (regime, method, scenario).
struct PooledCell {
  std::string regime, method, scenario;
  int runs = 0, failures = 0;
  // Pooled RMSE = sqrt(Σ n_i·rmse_i² / Σ n_i) with n_i the ATE pairs of run i: over the runs
  // that did not fail (one diverged run is counted as a failure and does not swamp the figure)
  // and over all runs.
  double rmse_ok = 0.0, rmse_all = 0.0;
  double median_ms = 0.0, p95_ms = 0.0, median_cpu_ms = 0.0;  // medians over the runs
  double drift_ok = 0.0;  // mean drift per 100 m [m] over the runs that did not fail
  // Summed over the runs: scans, scans reported `degenerate`, scans with a degenerate direction.
  int scans = 0, degenerate_scans = 0, degenerate_direction_scans = 0;
};

// Cells in the order regimes × scenarios × methods of first appearance in `rows`.
std::vector<PooledCell> PoolRows(const std::vector<RunRow>& rows);

// The cells as markdown table rows (with header) and as CSV (no timing: the part that is equal
// between a single job and merged split jobs).
std::string PooledTableMarkdown(const std::vector<PooledCell>& cells);
void WritePooledCsv(const std::string& path, const std::vector<PooledCell>& cells);

// A table2.svg bar label: `metres` in centimetres with two significant digits (0.26, 0.73, 1.3),
// so that close values of the small regimes stay apart (one decimal showed 0.26 and 0.34 cm both
// as 0.3).
std::string CentimetreLabel(double metres);

}  // namespace ctlio::lioapp
