// What ctlio_experiment writes beside its runs: one job of the experiment, the Table II markdown
// table with its SVG bar chart, and the NEES, calibration, extrinsic and observability tables of
// the jobs (docs/experiments/table2.md). Every file written is registered in `written`.
#pragma once

#include <string>
#include <vector>

#include "experiment_results.h"
#include "output_files.h"
#include "run_odometry.h"

namespace ctlio::lioapp {

// One run of the experiment: a regime's sequence through one method (and scenario).
struct ExperimentJob {
  std::string regime;
  int index = 0;
  std::string method;
  std::string scenario;
  double outage_s = 0.0;  // 0 = none
  RunSummary run;
  bool done = false;
  std::string error;
};

// OUT/extrinsic.csv: per run with a perturbed nominal or an estimated extrinsic, the starting
// and final extrinsic errors against the truth (rotation [deg], translation [cm]), the final
// marginal σ per axis ([ρ] cm, [φ] deg) and whether the error lies within 3σ on every axis, the
// ATE (sim/extrinsic_error.h), and with a calibration warm-up replay the scans it revised and the
// ATE of the trajectory as returned live (RunSummary::live_ate; = ate_m without a replay).
void WriteExtrinsicErrors(const std::string& out, const std::vector<ExperimentJob>& jobs,
                          OutputFiles* written);

// OUT/table.md, OUT/pooled.csv and OUT/table2.svg from the per-run rows.
void WriteTable(const std::string& out, const std::string& settings,
                const std::vector<RunRow>& rows, const std::string& provenance,
                OutputFiles* written);

// OUT/nees.csv (one line per run: mean NEES of the pose, its translation and rotation, the
// scans, and the error of every IMU's final bias estimate against the true initial bias) and
// OUT/nees.md (means per regime, method and scenario over the runs' scans; 6 resp. 3 if
// consistent).
void WriteNees(const std::string& out, const std::vector<ExperimentJob>& jobs,
               OutputFiles* written);

// OUT/calibration.csv (one line per run and IMU): the online calibration's final clock offset,
// its marginal σ, the simulated truth, the error and |error| ≤ 3σ, and the run's ATE; and the
// first and last σ (whether it shrinks: observability).
void WriteCalibration(const std::string& out, const std::vector<ExperimentJob>& jobs,
                      OutputFiles* written);

// OUT/observability.csv (one line per run and calibration coordinate, with the observability
// check of the online calibration, calibration_observability.h): ν after the last scan, whether
// the coordinate was unobservable then, and the fraction of the scans after which it was.
void WriteObservability(const std::string& out, const std::vector<ExperimentJob>& jobs,
                        OutputFiles* written);

}  // namespace ctlio::lioapp
