// Hyperparameter training of the 1D study on the validation set (SPEC §6): maximum marginal
// likelihood of the measurements (Kalman-filter innovations, exact for these linear-Gaussian
// models; for IMU as input only the positions are measurements), or, as an option, minimum
// validation position RMSE of the smoother.
#pragma once

#include <functional>
#include <vector>

#include "ctlio/study/estimators.h"

namespace ctlio::study {

// Σ_i f(i) over i in [0, n) with `threads` worker threads (deterministic: fixed partition,
// per-thread partial sums added in order).
double ParallelSum(int n, int threads, const std::function<double(int)>& f);
// Calls f(i, thread) for i in [0, n).
void ParallelFor(int n, int threads, const std::function<void(int, int)>& f);

// Minimises f on [lo, hi] by golden-section search to an interval width tol.
double GoldenSection(const std::function<double(double)>& f, double lo, double hi, double tol,
                     int* evaluations);
// Nelder–Mead simplex minimisation (2-D here, any dimension supported).
Eigen::VectorXd NelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                           const Eigen::VectorXd& start, const Eigen::VectorXd& step, double ftol,
                           int max_evaluations, int* evaluations);

// `trajectories` (full, with schedules) train IMU as measurement and the min-RMSE criterion;
// `input` holds the IMU-as-input summaries of those trajectories followed by any further
// validation trajectories that only the Q_k likelihood uses (see StudyConfig).
struct ValidationSet {
  std::vector<Trajectory> trajectories;
  std::vector<InputSchedule> schedules;
  std::vector<InputData> input;
};
ValidationSet MakeValidationSet(std::vector<Trajectory> trajectories,
                                std::vector<InputData> extra_input = {});

enum class TrainingCriterion { kMaxLikelihood, kMinRmse };

struct InputTraining {
  InputHyperparameters hyper;
  double objective;  // total log-likelihood, or position RMSE
  int evaluations;
};
struct MeasurementTraining {
  PriorConfig prior;
  double objective;
  int evaluations;
};

// `subset` > 0 limits the trajectories used (the RMSE criterion runs the smoother each time).
// The input likelihood uses every entry of set.input, the other criteria set.trajectories.
InputTraining TrainImuAsInput(const ValidationSet& set, const SensorModel& sensors,
                              TrainingCriterion criterion, int threads, int subset = 0);
MeasurementTraining TrainImuAsMeasurement(const ValidationSet& set, const SensorModel& sensors,
                                          TrainingCriterion criterion, int threads, int subset = 0);

}  // namespace ctlio::study
