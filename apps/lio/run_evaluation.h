// What ctlio_odometry reports of each run: evaluation.txt (one `key value` per line: counts, times
// [ms], ATE [m], the extrinsic and time offset against the truth, the calibration's observability)
// and the summary tables on stdout (docs/user-guide/outputs.md, programs.md).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "calibration_output.h"
#include "ctlio/io/dataset.h"
#include "output_files.h"
#include "run_odometry.h"

namespace ctlio::lioapp {

// The run's lines of evaluation.txt up to its ATE (`truth`: the source's ground truth, nullptr
// without; the ATE lines need it when run.ate is set). `recommended`: RecommendCalibration's.
void WriteRunEvaluation(const RunSummary& run,
                        const std::optional<RecommendedCalibration>& recommended,
                        const std::vector<io::StampedPose>* truth, std::ostream& ev);

// With online calibration: each IMU's final time offset, its σ and, simulated, its error.
void WriteTimeOffsetEvaluation(const RunSummary& run, std::ostream& ev);

// With online calibration: calibration.csv (and calibration_live.csv after a warm-up replay),
// calibration.yaml from `recommended` with a warning for the coordinates kept at their start, each
// registered in `files`, and the time offsets in evaluation.txt.
void WriteCalibrationOutputs(const std::string& out, const RunSummary& run,
                             const std::optional<RecommendedCalibration>& recommended,
                             OutputFiles* files, std::ostream& ev);

// The two tables of the summary (accuracy with the scan counts; time per scan [ms] and peak
// memory), their legends and the runs' input, gap and extrinsic warnings, on stdout.
void PrintRunTables(const std::vector<RunSummary>& runs);

}  // namespace ctlio::lioapp
