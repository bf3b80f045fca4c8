#include "ctlio/study/study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace ctlio::study {
namespace {

std::vector<Trajectory> SimulateSet(const DatasetConfig& dataset, const StudyConfig& config,
                                    int set_id, int count, int threads) {
  std::vector<Trajectory> out(count);
  const SensorConfig& sensors = set_id == kValidationSet && config.validation_sensors
                                    ? *config.validation_sensors
                                    : config.sensors;
  ParallelFor(count, threads,
              [&](int i, int) { out[i] = Simulate(dataset, sensors, config.seed, set_id, i); });
  return out;
}

std::ofstream Open(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(std::string(__FILE__) + ": cannot write " + path);
  f << std::setprecision(10);
  return f;
}

void WriteStats(const ErrorStatistics& s, const std::vector<double>& times,
                const std::string& path) {
  std::ofstream f = Open(path);
  static const char* kNames[] = {"p", "v", "a"};
  f << "t";
  for (int d = 0; d < s.dim(); ++d) f << ",mean_" << kNames[d];
  for (int d = 0; d < s.dim(); ++d) f << ",rmse_" << kNames[d];
  f << ",nees,nees_lower,nees_upper\n";
  for (int t = 0; t < s.num_times(); ++t) {
    f << times[t];
    const Eigen::VectorXd m = s.MeanError(t), r = s.Rmse(t);
    for (int d = 0; d < s.dim(); ++d) f << "," << m[d];
    for (int d = 0; d < s.dim(); ++d) f << "," << r[d];
    f << "," << s.MeanNees(t) << "," << s.NeesLower() << "," << s.NeesUpper() << "\n";
  }
}

std::string Vec(const Eigen::VectorXd& v) {
  std::ostringstream o;
  o << std::setprecision(8) << "[";
  for (int i = 0; i < v.size(); ++i) o << (i ? ", " : "") << v[i];
  o << "]";
  return o.str();
}

std::string StatsJson(const ErrorStatistics& s) {
  std::ostringstream o;
  o << std::setprecision(8) << "{\"rmse\": " << Vec(s.OverallRmse())
    << ", \"mean_error\": " << Vec(s.OverallMeanError())
    << ", \"mean_nees\": " << s.OverallMeanNees() << ", \"nees_bounds\": [" << s.NeesLower() << ", "
    << s.NeesUpper() << "], \"fraction_nees_inside\": " << s.FractionNeesInside()
    << ", \"trajectories\": " << s.count() << "}";
  return o.str();
}

}  // namespace

DatasetResult RunDataset(const DatasetConfig& dataset, const StudyConfig& config,
                         const Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto report = [&](const std::string& stage, int done, int total) {
    if (progress) progress(stage, done, total);
  };
  DatasetResult result;
  result.dataset = dataset;
  const SensorModel sensors = MakeSensorModel(dataset, config.sensors);

  report("simulate validation", 0, config.validation_trajectories);
  // Further validation trajectories for the Q_k likelihood, kept only as interval summaries.
  const int extra =
      std::max(0, config.input_validation_trajectories - config.validation_trajectories);
  std::vector<InputData> extra_input(extra);
  {
    const SensorConfig& vs =
        config.validation_sensors ? *config.validation_sensors : config.sensors;
    ParallelFor(extra, config.threads, [&](int i, int) {
      const Trajectory traj =
          Simulate(dataset, vs, config.seed, kValidationSet, config.validation_trajectories + i);
      extra_input[i] = SummarizeInputs(traj, BuildInputSchedule(traj));
    });
  }
  const ValidationSet validation = MakeValidationSet(
      SimulateSet(dataset, config, kValidationSet, config.validation_trajectories, config.threads),
      std::move(extra_input));
  report("train (max likelihood)", 0, 2);
  result.input_ml =
      TrainImuAsInput(validation, sensors, TrainingCriterion::kMaxLikelihood, config.threads);
  report("train (max likelihood)", 1, 2);
  result.measurement_ml =
      TrainImuAsMeasurement(validation, sensors, TrainingCriterion::kMaxLikelihood, config.threads);
  report("train (max likelihood)", 2, 2);
  if (config.min_rmse_training) {
    report("train (min RMSE)", 0, 2);
    result.input_rmse = TrainImuAsInput(validation, sensors, TrainingCriterion::kMinRmse,
                                        config.threads, config.min_rmse_subset);
    report("train (min RMSE)", 1, 2);
    result.measurement_rmse = TrainImuAsMeasurement(
        validation, sensors, TrainingCriterion::kMinRmse, config.threads, config.min_rmse_subset);
    report("train (min RMSE)", 2, 2);
    result.has_rmse_training = true;
  }

  const ImuAsInput input(sensors, result.input_ml.hyper);
  const ImuAsMeasurement measurement(sensors, result.measurement_ml.prior);
  const int threads = std::max(1, config.threads);
  const int n = config.test_trajectories;
  if (n <= 0) throw std::invalid_argument(std::string(__FILE__) + ": need test trajectories");
  // The evaluation times are the position times, identical for every trajectory.
  const Trajectory first = Simulate(dataset, config.sensors, config.seed, kTestSet, 0);
  for (const auto& m : first.position) result.times.push_back(first.Time(m.node));
  const int num_times = static_cast<int>(result.times.size());
  // Fixed chunks of consecutive trajectories, each accumulated in order and merged in chunk
  // order: the floating-point sums do not depend on the number of threads.
  constexpr int kChunk = 10;
  const int chunks = (n + kChunk - 1) / kChunk;
  std::vector<ErrorStatistics> input_stats(chunks, ErrorStatistics(num_times, 2));
  std::vector<ErrorStatistics> meas_stats(chunks, ErrorStatistics(num_times, 3));
  std::vector<double> het_mean(chunks, 0.0), het_cov(chunks, 0.0);
  result.samples.resize(std::min(config.samples_to_keep, n));
  std::mutex mutex;
  int done = 0;
  ParallelFor(chunks, threads, [&](int t, int) {
    for (int i = t * kChunk; i < std::min(n, (t + 1) * kChunk); ++i) {
      const Trajectory traj = Simulate(dataset, config.sensors, config.seed, kTestSet, i);
      const InputSchedule schedule = BuildInputSchedule(traj);
      TrajectoryEstimate e1 = input.Smooth(traj, schedule);
      TrajectoryEstimate e2 = measurement.Smooth(traj);
      input_stats[t].Add(traj, e1);
      meas_stats[t].Add(traj, e2);
      if (i < config.heterogeneous_checks) {
        const TrajectoryEstimate h = measurement.SmoothPreintegrated(traj);
        for (size_t k = 0; k < h.nodes.size(); ++k) {
          het_mean[t] = std::max(het_mean[t], (h.mean[k] - e2.mean[k]).cwiseAbs().maxCoeff());
          het_cov[t] =
              std::max(het_cov[t], (h.covariance[k] - e2.covariance[k]).cwiseAbs().maxCoeff());
        }
      }
      if (i < static_cast<int>(result.samples.size())) {
        result.samples[i] = SampleTrajectory{traj, std::move(e1), std::move(e2)};
      }
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (done % std::max(1, n / 20) == 0 || done == n) report("test", done, n);
    }
  });
  result.input_stats = input_stats[0];
  result.measurement_stats = meas_stats[0];
  for (int t = 1; t < chunks; ++t) {
    result.input_stats.Merge(input_stats[t]);
    result.measurement_stats.Merge(meas_stats[t]);
  }
  result.heterogeneous_max_mean_diff = *std::max_element(het_mean.begin(), het_mean.end());
  result.heterogeneous_max_cov_diff = *std::max_element(het_cov.begin(), het_cov.end());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string WriteDatasetResult(const DatasetResult& r, const std::string& dir,
                               const std::string& prefix) {
  const std::string base = dir + "/" + prefix;
  WriteStats(r.input_stats, r.times, base + "_input_stats.csv");
  WriteStats(r.measurement_stats, r.times, base + "_measurement_stats.csv");
  {
    std::ofstream f = Open(base + "_samples.csv");
    f << "sample,t,p,v,a,in_p,in_v,in_sp,in_sv,me_p,me_v,me_a,me_sp,me_sv,me_sa\n";
    for (size_t s = 0; s < r.samples.size(); ++s) {
      const auto& S = r.samples[s];
      for (size_t k = 0; k < S.input.nodes.size(); ++k) {
        const int node = S.input.nodes[k];
        const Eigen::Vector3d& x = S.trajectory.truth[node];
        f << s << "," << S.trajectory.Time(node) << "," << x[0] << "," << x[1] << "," << x[2];
        for (int d = 0; d < 2; ++d) f << "," << S.input.mean[k][d];
        for (int d = 0; d < 2; ++d) f << "," << std::sqrt(S.input.covariance[k](d, d));
        for (int d = 0; d < 3; ++d) f << "," << S.measurement.mean[k][d];
        for (int d = 0; d < 3; ++d) f << "," << std::sqrt(S.measurement.covariance[k](d, d));
        f << "\n";
      }
    }
  }
  std::ostringstream o;
  o << std::setprecision(8) << "{\"dataset\": \"" << r.dataset.name
    << "\", \"seconds\": " << r.seconds << ",\n  \"trained_ml\": {\"q_k\": " << r.input_ml.hyper.q_k
    << ", \"sigma2\": " << r.measurement_ml.prior.qc
    << ", \"alpha\": " << r.measurement_ml.prior.alpha << "}";
  if (r.has_rmse_training) {
    o << ",\n  \"trained_min_rmse\": {\"q_k\": " << r.input_rmse.hyper.q_k
      << ", \"sigma2\": " << r.measurement_rmse.prior.qc
      << ", \"alpha\": " << r.measurement_rmse.prior.alpha << "}";
  }
  o << ",\n  \"imu_as_input\": " << StatsJson(r.input_stats)
    << ",\n  \"imu_as_measurement\": " << StatsJson(r.measurement_stats)
    << ",\n  \"heterogeneous_preintegration_max_diff\": {\"mean\": "
    << r.heterogeneous_max_mean_diff << ", \"covariance\": " << r.heterogeneous_max_cov_diff
    << "}}";
  return o.str();
}

}  // namespace ctlio::study
