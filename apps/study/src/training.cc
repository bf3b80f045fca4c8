#include "ctlio/study/training.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <thread>

namespace ctlio::study {

void ParallelFor(int n, int threads, const std::function<void(int, int)>& f) {
  threads = std::max(1, std::min(threads, n));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) f(i, 0);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(threads);
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t]() {
      try {
        for (int i = t; i < n; i += threads) f(i, t);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

double ParallelSum(int n, int threads, const std::function<double(int)>& f) {
  std::vector<double> terms(n, 0.0);
  ParallelFor(n, threads, [&](int i, int) { terms[i] = f(i); });
  return std::accumulate(terms.begin(), terms.end(), 0.0);
}

double GoldenSection(const std::function<double(double)>& f, double lo, double hi, double tol,
                     int* evaluations) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi;
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = f(c), fd = f(d);
  int evals = 2;
  while (b - a > tol) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - r * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + r * (b - a);
      fd = f(d);
    }
    ++evals;
  }
  if (evaluations != nullptr) *evaluations = evals;
  return 0.5 * (a + b);
}

Eigen::VectorXd NelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                           const Eigen::VectorXd& start, const Eigen::VectorXd& step, double ftol,
                           int max_evaluations, int* evaluations) {
  const int n = static_cast<int>(start.size());
  std::vector<Eigen::VectorXd> x(n + 1, start);
  std::vector<double> fx(n + 1);
  for (int i = 0; i < n; ++i) x[i + 1][i] += step[i];
  int evals = 0;
  for (int i = 0; i <= n; ++i, ++evals) fx[i] = f(x[i]);
  std::vector<int> order(n + 1);
  while (evals < max_evaluations) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return fx[a] < fx[b]; });
    const int best = order[0], worst = order[n], second = order[n - 1];
    double size = 0.0;
    for (int i = 0; i <= n; ++i) size = std::max(size, (x[i] - x[best]).cwiseAbs().maxCoeff());
    // Converged when the simplex is tiny or its values agree to ftol (relative).
    if (size < 1e-4 || std::abs(fx[worst] - fx[best]) <= ftol * (std::abs(fx[best]) + 1e-300)) {
      break;
    }
    Eigen::VectorXd centroid = Eigen::VectorXd::Zero(n);
    for (int i = 0; i <= n; ++i) {
      if (i != worst) centroid += x[i];
    }
    centroid /= n;
    const Eigen::VectorXd xr = centroid + (centroid - x[worst]);
    const double fr = f(xr);
    ++evals;
    if (fr < fx[best]) {
      const Eigen::VectorXd xe = centroid + 2.0 * (centroid - x[worst]);
      const double fe = f(xe);
      ++evals;
      if (fe < fr) {
        x[worst] = xe;
        fx[worst] = fe;
      } else {
        x[worst] = xr;
        fx[worst] = fr;
      }
    } else if (fr < fx[second]) {
      x[worst] = xr;
      fx[worst] = fr;
    } else {
      const bool outside = fr < fx[worst];
      const Eigen::VectorXd xc = outside ? Eigen::VectorXd(centroid + 0.5 * (xr - centroid))
                                         : Eigen::VectorXd(centroid + 0.5 * (x[worst] - centroid));
      const double fc = f(xc);
      ++evals;
      if (fc < std::min(fr, fx[worst])) {
        x[worst] = xc;
        fx[worst] = fc;
      } else {
        for (int i = 0; i <= n; ++i) {
          if (i == best) continue;
          x[i] = x[best] + 0.5 * (x[i] - x[best]);
          fx[i] = f(x[i]);
          ++evals;
        }
      }
    }
  }
  if (evaluations != nullptr) *evaluations = evals;
  const int best = static_cast<int>(std::min_element(fx.begin(), fx.end()) - fx.begin());
  return x[best];
}

ValidationSet MakeValidationSet(std::vector<Trajectory> trajectories,
                                std::vector<InputData> extra_input) {
  ValidationSet set;
  set.trajectories = std::move(trajectories);
  for (const auto& t : set.trajectories) {
    set.schedules.push_back(BuildInputSchedule(t));
    set.input.push_back(SummarizeInputs(t, set.schedules.back()));
  }
  for (auto& d : extra_input) set.input.push_back(std::move(d));
  return set;
}

namespace {

int SubsetSize(const ValidationSet& set, int subset) {
  const int n = static_cast<int>(set.trajectories.size());
  if (n == 0) throw std::invalid_argument(std::string(__FILE__) + ": empty validation set");
  return subset > 0 ? std::min(subset, n) : n;
}

double PositionMse(const Trajectory& traj, const TrajectoryEstimate& est) {
  double s = 0.0;
  for (size_t t = 0; t < est.nodes.size(); ++t) {
    const double e = est.mean[t][0] - traj.truth[est.nodes[t]][0];
    s += e * e;
  }
  return s / static_cast<double>(est.nodes.size());
}

}  // namespace

InputTraining TrainImuAsInput(const ValidationSet& set, const SensorModel& sensors,
                              TrainingCriterion criterion, int threads, int subset) {
  const int n = criterion == TrainingCriterion::kMaxLikelihood
                    ? static_cast<int>(subset > 0 ? std::min<size_t>(subset, set.input.size())
                                                  : set.input.size())
                    : SubsetSize(set, subset);
  if (n == 0) throw std::invalid_argument(std::string(__FILE__) + ": empty validation set");
  // Search on log Q_k: the objective is smooth and unimodal in it; [1e-6, 10] m²/s⁴.
  auto objective = [&](double log_q) {
    const ImuAsInput est(sensors, InputHyperparameters{std::exp(log_q)});
    if (criterion == TrainingCriterion::kMaxLikelihood) {
      return -ParallelSum(n, threads, [&](int i) { return est.LogLikelihood(set.input[i]); });
    }
    return std::sqrt(ParallelSum(n, threads,
                                 [&](int i) {
                                   return PositionMse(
                                       set.trajectories[i],
                                       est.Smooth(set.trajectories[i], set.schedules[i]));
                                 }) /
                     n);
  };
  InputTraining result;
  const double log_q =
      GoldenSection(objective, std::log(1e-6), std::log(10.0), 1e-4, &result.evaluations);
  result.hyper.q_k = std::exp(log_q);
  result.objective = objective(log_q);
  if (criterion == TrainingCriterion::kMaxLikelihood) result.objective = -result.objective;
  return result;
}

MeasurementTraining TrainImuAsMeasurement(const ValidationSet& set, const SensorModel& sensors,
                                          TrainingCriterion criterion, int threads, int subset) {
  const int n = SubsetSize(set, subset);
  // Parameters u = [log σ², α'] with α = |α'| (keeps α >= 0 without a constraint; the simplex
  // can reach α = 0 for WNOJ data).
  auto prior_of = [](const Eigen::VectorXd& u) {
    return PriorConfig{std::exp(u[0]), std::abs(u[1])};
  };
  auto objective = [&](const Eigen::VectorXd& u) {
    const ImuAsMeasurement est(sensors, prior_of(u));
    if (criterion == TrainingCriterion::kMaxLikelihood) {
      return -ParallelSum(n, threads,
                          [&](int i) { return est.LogLikelihood(set.trajectories[i]); });
    }
    return std::sqrt(ParallelSum(n, threads,
                                 [&](int i) {
                                   return PositionMse(set.trajectories[i],
                                                      est.Smooth(set.trajectories[i]));
                                 }) /
                     n);
  };
  MeasurementTraining result;
  // Start away from the truth (σ² = 0.5, α = 2) so that the search, not the start, finds it.
  Eigen::VectorXd u = NelderMead(objective, Eigen::Vector2d(std::log(0.5), 2.0),
                                 Eigen::Vector2d(0.7, 4.0), 1e-10, 300, &result.evaluations);
  result.prior = prior_of(u);
  result.objective = objective(u);
  if (criterion == TrainingCriterion::kMaxLikelihood) result.objective = -result.objective;
  return result;
}

}  // namespace ctlio::study
