// The project's scoreboard (docs/experiments/scoreboard.md): Singer-LIO against the IMU-as-input
// baseline over sensors × worlds × motions. Each cell is one ctlio_experiment output folder (its
// settings.txt names the world and the sensor's config, its results.csv holds one line per run);
// this part pools every cell's runs per method and compares the two methods cell by cell.
//
// Per cell and method: ATE as the RMS over the runs of each run's RMSE ATE (every run, a failed one
// included: a diverged run must show), drift per 100 m (mean over the runs that did not fail),
// failed scans (summed) and failed runs, CPU per scan of the odometry thread (median over the runs
// of each run's median, and of each run's p95). Per cell: CPU ratio Singer-LIO / baseline, the
// winner on ATE and on CPU, and whether the target holds there (Singer-LIO's ATE ≤ the
// baseline's, its CPU median ≤ the baseline's, 0 failed scans).
#pragma once

#include <string>
#include <vector>

#include "experiment_results.h"

namespace ctlio::lioapp {

// One cell's runs with its labels.
struct ScoreboardCellRuns {
  std::string sensor, world;  // the regime is each row's own
  double duration_s = 0.0;
  std::vector<RunRow> rows;
};

// Reads a ctlio_experiment output folder: `sensor` from settings.txt's `sensor` line, else the
// config's file name without `.yaml` (the shipped per-sensor config data/sensors/<sensor>.yaml),
// `world` and `duration_s` from settings.txt, the rows from results.csv. Throws naming the file.
ScoreboardCellRuns ReadScoreboardCell(const std::string& dir);

struct MethodScore {
  std::string method;
  int runs = 0, failed_runs = 0, failed_scans = 0;
  double ate_rms_m = 0.0;         // sqrt(mean over runs of rmse²); NaN when no run has an ATE
  double drift_m_per_100m = 0.0;  // mean over the non-failed runs; NaN when none
  double cpu_median_ms = 0.0, cpu_p95_ms = 0.0;  // medians over the runs
};

struct ScoreboardRow {
  std::string sensor, world, regime;
  std::vector<int> sequences;  // the indices run (those of the first method)
  MethodScore singer, baseline;
  double cpu_ratio = 0.0;  // singer.cpu_median_ms / baseline.cpu_median_ms
  // "singer_lio", "imu_input" or "tie" (equal to 0.01 mm resp. 0.05 ms, the printed digits).
  std::string ate_winner, cpu_winner;
  bool target_met = false;  // Singer-LIO ATE ≤ baseline, CPU median ≤ baseline, 0 failed scans
};

// Scores one method's runs of `regime` among `rows`: throws when it has none.
MethodScore ScoreMethod(const std::vector<RunRow>& rows, const std::string& regime,
                        const std::string& method);

// One row per (cell, regime) in the order given; `singer` and `baseline` name the two methods
// compared. Throws naming the cell when a method or a sequence is missing (both methods must have
// run the same sequences, or the comparison would be unequal).
std::vector<ScoreboardRow> ScoreCells(const std::vector<ScoreboardCellRuns>& cells,
                                      const std::string& singer = "singer_lio",
                                      const std::string& baseline = "imu_input");

// Machine-readable: one line per row, both methods' numbers side by side.
void WriteScoreboardCsv(const std::string& path, const std::vector<ScoreboardRow>& rows);

// The Markdown table (header line included) and a summary line: cells where the target holds,
// where Singer-LIO wins ATE / CPU, failed runs per method.
std::string ScoreboardMarkdown(const std::vector<ScoreboardRow>& rows);
std::string ScoreboardSummary(const std::vector<ScoreboardRow>& rows);

}  // namespace ctlio::lioapp
