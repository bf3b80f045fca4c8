// The expectations of issue 7 (SPEC §6) on reduced but sufficient setups: trained
// hyperparameters against the paper's, the Q_k calibration formula, consistency (NEES inside the
// two-sided 95% χ² bounds), unbiasedness, and equal position RMSE of the two estimators.
#include "ctlio/study/study.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ctlio/study/evaluation.h"
#include "ctlio/study/training.h"

namespace ctlio::study {
namespace {

constexpr uint64_t kSeed = 1;  // the program's default seed
constexpr int kThreads = 2;

ValidationSet MakeSet(const DatasetConfig& data, const SensorConfig& sensors, int count) {
  std::vector<Trajectory> trajectories(count);
  ParallelFor(count, kThreads, [&](int i, int) {
    trajectories[i] = Simulate(data, sensors, kSeed, kValidationSet, i);
  });
  return MakeValidationSet(std::move(trajectories));
}

struct PaperFit {
  DatasetConfig data;
  double q_k;  // the paper's trained input covariance
};

// Default sensors (400 Hz, σ_acc 0.05, 10 Hz positions σ 0.01, 10 s); Q_k from the full
// 100-trajectory validation set; σ², α from its first 25 trajectories (the likelihood of
// 4000 accelerometer samples per trajectory pins them down: ±0.8% and ±0.3 expected).
TEST(Training, ReproducesThePapersHyperparameters) {
  const SensorConfig sensors;
  for (const PaperFit& fit :
       {PaperFit{WnojDataset(), 0.00338}, PaperFit{SingerDataset(), 0.00283}}) {
    const ValidationSet set = MakeSet(fit.data, sensors, 100);
    const SensorModel model = MakeSensorModel(fit.data, sensors);
    const InputTraining input =
        TrainImuAsInput(set, model, TrainingCriterion::kMaxLikelihood, kThreads);
    EXPECT_NEAR(input.hyper.q_k, fit.q_k, 0.2 * fit.q_k) << fit.data.name;
    const MeasurementTraining meas =
        TrainImuAsMeasurement(set, model, TrainingCriterion::kMaxLikelihood, kThreads, 25);
    EXPECT_NEAR(meas.prior.qc, 1.0, 0.03) << fit.data.name;
    if (fit.data.prior.alpha == 0.0) {
      EXPECT_LT(meas.prior.alpha, 0.5);
    } else {
      EXPECT_NEAR(meas.prior.alpha, 10.0, 1.0);
    }
  }
}

TEST(Training, WnojInputCovarianceFollowsCalibrationFormula) {
  // Q_k = σ_acc² + Qc·Δt/3 (SPEC §6) on a large validation set (400 trajectories).
  const SensorConfig sensors;
  const DatasetConfig data = WnojDataset();
  const ValidationSet set = MakeSet(data, sensors, 400);
  const InputTraining input = TrainImuAsInput(set, MakeSensorModel(data, sensors),
                                              TrainingCriterion::kMaxLikelihood, kThreads);
  const double expected = 0.05 * 0.05 + 1.0 * (1.0 / 400.0) / 3.0;
  EXPECT_NEAR(input.hyper.q_k, expected, 0.05 * expected);
}

TEST(Training, MinRmseCriterionRunsAndStaysNearTheLikelihoodFit) {
  const SensorConfig sensors;
  const DatasetConfig data = SingerDataset();
  const ValidationSet set = MakeSet(data, sensors, 4);
  const SensorModel model = MakeSensorModel(data, sensors);
  const InputTraining input = TrainImuAsInput(set, model, TrainingCriterion::kMinRmse, kThreads);
  // RMSE is flat in Q_k; only require a sane value (within a factor 5 of the paper's).
  EXPECT_GT(input.hyper.q_k, 0.00283 / 5);
  EXPECT_LT(input.hyper.q_k, 0.00283 * 5);
  EXPECT_GT(input.objective, 0.0);
  EXPECT_LT(input.objective, 0.01);
}

TEST(Optimisers, FindKnownMinima) {
  int evals = 0;
  EXPECT_NEAR(GoldenSection([](double x) { return (x - 1.3) * (x - 1.3); }, -5, 5, 1e-8, &evals),
              1.3, 1e-7);
  const Eigen::VectorXd x = NelderMead(
      [](const Eigen::VectorXd& u) {
        return 100 * std::pow(u[1] - u[0] * u[0], 2) + std::pow(1 - u[0], 2);
      },
      Eigen::Vector2d(-1.2, 1.0), Eigen::Vector2d(0.5, 0.5), 1e-14, 2000, &evals);
  EXPECT_NEAR(x[0], 1.0, 1e-3);
  EXPECT_NEAR(x[1], 1.0, 2e-3);
}

TEST(Evaluation, NeesBoundsAreChiSquareQuantiles) {
  double lo, hi;
  NeesBounds(1, 2, 0.05, &lo, &hi);  // χ²(2): quantiles −2 ln(1 − p)
  EXPECT_NEAR(lo, -2.0 * std::log(1.0 - 0.025), 1e-10);
  EXPECT_NEAR(hi, -2.0 * std::log(0.025), 1e-10);
  NeesBounds(1000, 3, 0.05, &lo, &hi);
  EXPECT_LT(lo, 3.0);
  EXPECT_GT(hi, 3.0);
  EXPECT_NEAR(hi - 3.0, 3.0 - lo, 0.01);
}

// Test set with the paper's hyperparameters: both estimators unbiased and consistent, equal
// position RMSE (the paper: "perform identically").
struct PaperSetup {
  DatasetConfig data;
  InputHyperparameters input;
  PriorConfig prior;
};

TEST(TestSet, BothEstimatorsUnbiasedConsistentAndIdentical) {
  StudyConfig config;
  const int M = 200;
  for (const PaperSetup& setup : {PaperSetup{WnojDataset(), {0.00338}, {1.0069, 0.0}},
                                  PaperSetup{SingerDataset(), {0.00283}, {1.0074, 10.2442}}}) {
    const SensorModel model = MakeSensorModel(setup.data, config.sensors);
    const ImuAsInput input(model, setup.input);
    const ImuAsMeasurement meas(model, setup.prior);
    const Trajectory first = Simulate(setup.data, config.sensors, kSeed, kTestSet, 0);
    const int T = static_cast<int>(first.position.size());
    std::vector<ErrorStatistics> s1(kThreads, ErrorStatistics(T, 2)),
        s2(kThreads, ErrorStatistics(T, 3));
    ParallelFor(M, kThreads, [&](int i, int t) {
      const Trajectory traj = Simulate(setup.data, config.sensors, kSeed, kTestSet, i);
      s1[t].Add(traj, input.Smooth(traj, BuildInputSchedule(traj)));
      s2[t].Add(traj, meas.Smooth(traj));
    });
    for (int t = 1; t < kThreads; ++t) {
      s1[0].Merge(s1[t]);
      s2[0].Merge(s2[t]);
    }
    const ErrorStatistics& a = s1[0];
    const ErrorStatistics& b = s2[0];
    ASSERT_EQ(a.count(), M);
    EXPECT_GE(b.FractionNeesInside(), 0.9) << setup.data.name;
    EXPECT_GE(a.FractionNeesInside(), 0.8) << setup.data.name;
    const double rp_a = a.OverallRmse()[0], rp_b = b.OverallRmse()[0];
    EXPECT_NEAR(rp_a / rp_b, 1.0, 0.05) << setup.data.name;
    // Unbiased: the mean error at each time is within 3 standard errors at >= 95% of the times.
    for (const ErrorStatistics* s : {&a, &b}) {
      int inside = 0;
      for (int t = 0; t < T; ++t) {
        inside += std::abs(s->MeanError(t)[0]) <= 3.0 * s->Rmse(t)[0] / std::sqrt(M) ? 1 : 0;
      }
      EXPECT_GE(inside, 0.95 * T) << setup.data.name;
    }
  }
}

TEST(Extensions, TwoAsynchronousAccelerometersHelpImuAsMeasurement) {
  // A second accelerometer (other rate, other offset) only adds measurements to IMU as
  // measurement, so the posterior variance at the position times can only shrink.
  SensorConfig one;
  one.duration_s = 3.0;
  one.accelerometers = {{100.0, 0.0, 0.05}};
  SensorConfig two = one;
  two.accelerometers.push_back({70.0, 0.0031, 0.05});
  const DatasetConfig data = SingerDataset();
  const Trajectory t1 = Simulate(data, one, kSeed, kTestSet, 0);
  const Trajectory t2 = Simulate(data, two, kSeed, kTestSet, 0);
  const TrajectoryEstimate e1 = ImuAsMeasurement(MakeSensorModel(data, one), data.prior).Smooth(t1);
  const TrajectoryEstimate e2 = ImuAsMeasurement(MakeSensorModel(data, two), data.prior).Smooth(t2);
  ASSERT_EQ(e1.nodes.size(), e2.nodes.size());
  for (size_t k = 0; k < e1.nodes.size(); ++k) {
    for (int d = 0; d < 3; ++d) {
      EXPECT_LE(e2.covariance[k](d, d), e1.covariance[k](d, d) * (1 + 1e-9)) << k << " " << d;
    }
  }
  // IMU as input merges both streams (zero-order hold of the newest sample of either).
  const InputSchedule schedule = BuildInputSchedule(t2);
  int from_second = 0;
  for (const auto& interval : schedule.intervals)
    for (const auto& h : interval) from_second += h.sensor == 1 ? 1 : 0;
  EXPECT_GT(from_second, 150);
  const ImuAsInput in(MakeSensorModel(data, two), InputHyperparameters{0.003});
  EXPECT_EQ(in.Smooth(t2, schedule).nodes.size(), t2.position.size());
}

TEST(Extensions, DropoutKeepsBothEstimatorsRunning) {
  SensorConfig sensors;
  sensors.duration_s = 3.0;
  sensors.dropout_start_s = 1.0;
  sensors.dropout_end_s = 2.0;
  const DatasetConfig data = WnojDataset();
  const Trajectory traj = Simulate(data, sensors, kSeed, kTestSet, 0);
  for (const auto& m : traj.accel[0]) {
    const double t = traj.Time(m.node);
    EXPECT_TRUE(t < 1.0 || t >= 2.0);
  }
  const SensorModel model = MakeSensorModel(data, sensors);
  const ImuAsInput input(model, InputHyperparameters{0.00338});
  const InputSchedule schedule = BuildInputSchedule(traj);
  // Inside the gap the held sample ages and the input variance grows.
  double max_age = 0.0;
  for (const auto& interval : schedule.intervals)
    for (const auto& h : interval) max_age = std::max(max_age, h.age);
  EXPECT_NEAR(max_age, 1.0, 0.11);
  EXPECT_GT(input.StretchVariance({0.1, 0.0, 0.5, 0}), 0.00338);
  EXPECT_EQ(input.Smooth(traj, schedule).nodes.size(), traj.position.size());
  const ImuAsMeasurement meas(model, data.prior);
  EXPECT_EQ(meas.Smooth(traj).nodes.size(), traj.position.size());
}

TEST(Simulation, BadConfigurationsThrow) {
  SensorConfig s;
  s.accelerometers.clear();
  EXPECT_THROW(Simulate(WnojDataset(), s, 1, 1, 0), std::invalid_argument);
  s = SensorConfig{};
  s.sigma_position = 0.0;
  EXPECT_THROW(Simulate(WnojDataset(), s, 1, 1, 0), std::invalid_argument);
  s = SensorConfig{};
  s.accelerometers[0].offset_s = 0.01;  // IMU as input needs a sample at t = 0
  const Trajectory traj = Simulate(WnojDataset(), s, 1, 1, 0);
  EXPECT_THROW(BuildInputSchedule(traj), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::study
