// The 1D study as a library (apps/study_1d.cpp is its command line): for one dataset (WNOJ or
// Singer ground truth) and one sensor setup, simulate the validation and test sets, train both
// estimators, smooth every test trajectory and collect the statistics (SPEC §6).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/study/evaluation.h"
#include "ctlio/study/training.h"

namespace ctlio::study {

struct StudyConfig {
  SensorConfig sensors;
  // Sensors of the validation set when they differ from the test set's (the dropout scenario
  // trains on nominal data: a dropout is an event at test time, not a property of the sensor).
  std::optional<SensorConfig> validation_sensors;
  int validation_trajectories = 100;
  // Validation trajectories of the IMU-as-input likelihood (the first `validation_trajectories`
  // of the same stream, then more). Its only measurements are the positions, which say little
  // about Q_k: the Cramér–Rao spread of the fitted Q_k is ±11% with 100 trajectories, ±3.6%
  // with 1000 and ±2% with 3000, and the input estimator's NEES at 1000 test trajectories
  // leaves the χ² bounds at most times once Q_k is ~10% off (docs/experiments/study-1d.md). A
  // deviation from SPEC §6's 100 validation trajectories, which cannot pin Q_k down. 0 = use the
  // `validation_trajectories` only.
  int input_validation_trajectories = 3000;
  int test_trajectories = 1000;
  // The seed of the study's first run, kept on principle: it was fixed before any result was
  // seen (docs/experiments/study-1d.md reports other seeds beside it).
  uint64_t seed = 20250301;
  // Worker threads; results do not depend on it (test trajectories are accumulated in fixed
  // chunks merged in index order, sums over trajectories are taken in index order).
  int threads = 2;
  bool min_rmse_training = true;  // also train by minimum validation RMSE (reported beside)
  int min_rmse_subset = 20;       // validation trajectories used by that criterion
  int heterogeneous_checks = 3;   // test trajectories solved both ways (preintegrated vs batch)
  int samples_to_keep = 3;        // test trajectories kept for the plots
};

// Set ids of the random streams.
inline constexpr int kValidationSet = 1;
inline constexpr int kTestSet = 2;

struct SampleTrajectory {
  Trajectory trajectory;
  TrajectoryEstimate input;
  TrajectoryEstimate measurement;
};

struct DatasetResult {
  DatasetConfig dataset;
  InputTraining input_ml, input_rmse;
  MeasurementTraining measurement_ml, measurement_rmse;
  bool has_rmse_training = false;
  ErrorStatistics input_stats{0, 2};
  ErrorStatistics measurement_stats{0, 3};
  std::vector<double> times;  // evaluation times (s)
  std::vector<SampleTrajectory> samples;
  double heterogeneous_max_mean_diff = 0.0;  // max |preintegrated − batch| over checked runs
  double heterogeneous_max_cov_diff = 0.0;
  double seconds = 0.0;
};

using Progress = std::function<void(const std::string& stage, int done, int total)>;

DatasetResult RunDataset(const DatasetConfig& dataset, const StudyConfig& config,
                         const Progress& progress);

// Writes <dir>/<prefix>_{input,measurement}_stats.csv (per time: mean error, RMSE, NEES and
// bounds), <prefix>_samples.csv and returns a JSON object string with the summary.
std::string WriteDatasetResult(const DatasetResult& result, const std::string& dir,
                               const std::string& prefix);

}  // namespace ctlio::study
