// ctlio_study_1d_calibration: how the maximum-likelihood input covariance Q_k of IMU as input
// (and optionally σ², α of IMU as measurement) depends on the seed and on the size of the
// validation set, with the Cramér–Rao spread from the curvature of the log-likelihood.
#include <gflags/gflags.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "common/command_line.h"
#include "ctlio/study/evaluation.h"
#include "ctlio/study/study.h"

DEFINE_string(seeds, "20250301,1,2,3", "comma-separated seeds");
DEFINE_int32(validation, 100, "validation trajectories");
DEFINE_double(accel_rate, 400.0, "accelerometer rate [Hz]");
DEFINE_double(sigma_acc, 0.05, "accelerometer noise σ [m/s²]");
DEFINE_double(sigma_pos, 0.01, "position noise σ [m]");
DEFINE_int32(threads, 2, "threads");
DEFINE_int32(set_id, 1, "random stream (1 validation, 2 test)");
DEFINE_bool(measurement, false, "also train sigma^2, alpha (IMU as measurement)");
DEFINE_string(nees_q, "", "instead: IMU-as-input NEES on the test set for these Q_k (comma list)");
DEFINE_int32(test, 1000, "test trajectories for --nees_q");

using namespace ctlio::study;

constexpr char kUsage[] =
    "ctlio_study_1d_calibration: how the maximum-likelihood input covariance Q_k of IMU as input\n"
    "(and sigma^2, alpha of IMU as measurement) depends on the seed and the validation size.\n"
    "\n"
    "  ctlio_study_1d_calibration --seeds=20250301,1,2,3 --validation=100\n"
    "  ctlio_study_1d_calibration --nees_q=0.01,0.02 --test=1000";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  std::vector<uint64_t> seeds;
  std::stringstream ss(FLAGS_seeds);
  for (std::string s; std::getline(ss, s, ',');) seeds.push_back(std::stoull(s));
  SensorConfig sensors;
  sensors.accelerometers = {{FLAGS_accel_rate, 0.0, FLAGS_sigma_acc}};
  sensors.sigma_position = FLAGS_sigma_pos;
  // Log-likelihood of every trajectory on a grid of log Q_k, summed; trajectories regenerated
  // on the fly so that any set size fits in memory.
  if (!FLAGS_nees_q.empty()) {
    std::vector<double> qs;
    std::stringstream qss(FLAGS_nees_q);
    for (std::string s; std::getline(qss, s, ',');) qs.push_back(std::stod(s));
    for (const DatasetConfig& data : {WnojDataset(), SingerDataset()}) {
      const SensorModel model = MakeSensorModel(data, sensors);
      for (uint64_t seed : seeds) {
        const int T = static_cast<int>(Simulate(data, sensors, seed, 2, 0).position.size());
        std::vector<std::vector<ErrorStatistics>> st(
            qs.size(), std::vector<ErrorStatistics>(FLAGS_threads, ErrorStatistics(T, 2)));
        ParallelFor(FLAGS_test, FLAGS_threads, [&](int i, int t) {
          const Trajectory traj = Simulate(data, sensors, seed, 2, i);
          const InputSchedule sched = BuildInputSchedule(traj);
          for (size_t k = 0; k < qs.size(); ++k)
            st[k][t].Add(traj, ImuAsInput(model, InputHyperparameters{qs[k]}).Smooth(traj, sched));
        });
        for (size_t k = 0; k < qs.size(); ++k) {
          for (int t = 1; t < FLAGS_threads; ++t) st[k][0].Merge(st[k][t]);
          std::printf(
              "%s seed %llu Q_k %.5f: NEES %.3f (%.3f-%.3f) inside %.0f%%  rmse p %.4f mm\n",
              data.name.c_str(), static_cast<unsigned long long>(seed), qs[k],
              st[k][0].OverallMeanNees(), st[k][0].NeesLower(), st[k][0].NeesUpper(),
              100 * st[k][0].FractionNeesInside(), 1e3 * st[k][0].OverallRmse()[0]);
        }
        std::fflush(stdout);
      }
    }
    return 0;
  }
  const int K = 81;
  const double lo = std::log(1e-3), hi = std::log(1e-2);
  for (const DatasetConfig& data : {WnojDataset(), SingerDataset()}) {
    const SensorModel model = MakeSensorModel(data, sensors);
    for (uint64_t seed : seeds) {
      std::vector<std::vector<double>> ll(FLAGS_threads, std::vector<double>(K, 0.0));
      // Deterministic: per-trajectory terms stored, summed in order.
      std::vector<std::vector<double>> terms(FLAGS_validation, std::vector<double>(K));
      ParallelFor(FLAGS_validation, FLAGS_threads, [&](int i, int) {
        const Trajectory traj = Simulate(data, sensors, seed, FLAGS_set_id, i);
        const InputSchedule sched = BuildInputSchedule(traj);
        for (int k = 0; k < K; ++k) {
          const double q = std::exp(lo + (hi - lo) * k / (K - 1));
          terms[i][k] = ImuAsInput(model, InputHyperparameters{q}).LogLikelihood(traj, sched);
        }
      });
      std::vector<double> tot(K, 0.0);
      for (int i = 0; i < FLAGS_validation; ++i)
        for (int k = 0; k < K; ++k) tot[k] += terms[i][k];
      int best = 0;
      for (int k = 1; k < K; ++k)
        if (tot[k] > tot[best]) best = k;
      best = std::min(std::max(best, 1), K - 2);
      const double h = (hi - lo) / (K - 1);
      const double d1 = (tot[best + 1] - tot[best - 1]) / (2 * h);
      const double d2 = (tot[best + 1] - 2 * tot[best] + tot[best - 1]) / (h * h);
      const double x = lo + h * best - d1 / d2;
      std::printf("%s seed %llu N %d: Q_k %.6f  (CRLB std of log Q_k %.3f)\n", data.name.c_str(),
                  static_cast<unsigned long long>(seed), FLAGS_validation, std::exp(x),
                  1.0 / std::sqrt(-d2));
      if (FLAGS_measurement) {
        std::vector<Trajectory> trajs(FLAGS_validation);
        ParallelFor(FLAGS_validation, FLAGS_threads,
                    [&](int i, int) { trajs[i] = Simulate(data, sensors, seed, FLAGS_set_id, i); });
        const ValidationSet set = MakeValidationSet(std::move(trajs));
        const MeasurementTraining m =
            TrainImuAsMeasurement(set, model, TrainingCriterion::kMaxLikelihood, FLAGS_threads);
        std::printf("   sigma2 %.5f alpha %.4f\n", m.prior.qc, m.prior.alpha);
      }
      std::fflush(stdout);
    }
  }
  return 0;
}
