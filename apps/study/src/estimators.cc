#include "ctlio/study/estimators.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "ctlio/solvers/schur_complement.h"
#include "ctlio/study/chain_smoother.h"
#include "ctlio/study/measurement_factors.h"
#include "ctlio/study/motion.h"
#include "ctlio/study/prior_factor.h"

namespace ctlio::study {
namespace {

std::string Where(int line) { return std::string(__FILE__) + ":" + std::to_string(line) + ": "; }

constexpr double kLog2Pi = 1.8378770664093453;

// Scalar Kalman update of component `index` with measurement z, variance r; returns the
// log-likelihood of the innovation.
template <int D>
double ScalarUpdate(int index, double z, double r, Eigen::Matrix<double, D, 1>* x,
                    Eigen::Matrix<double, D, D>* P) {
  const double s = (*P)(index, index) + r;
  const double nu = z - (*x)[index];
  const Eigen::Matrix<double, D, 1> K = P->col(index) / s;
  *x += K * nu;
  *P -= K * K.transpose() * s;
  *P = 0.5 * (*P + P->transpose()).eval();
  return -0.5 * (nu * nu / s + std::log(s) + kLog2Pi);
}

void CheckPositions(const Trajectory& traj) {
  if (traj.position.size() < 2 || traj.position.front().node != 0) {
    throw std::invalid_argument(Where(__LINE__) +
                                "need >= 2 positions and the first one at the first grid time");
  }
}

// Adds the Gauss-Newton terms of `cost` linearised at `at` into a dense system;
// offsets[b] is the first row of parameter block b.
void AddFactorDense(const ceres::CostFunction& cost, const std::vector<int>& offsets,
                    const std::vector<const double*>& at, Eigen::MatrixXd* H, Eigen::VectorXd* g) {
  const auto& sizes = cost.parameter_block_sizes();
  const int m = cost.num_residuals();
  std::vector<std::vector<double>> params(sizes.size()), jac(sizes.size());
  std::vector<const double*> pp(sizes.size());
  std::vector<double*> jp(sizes.size());
  for (size_t b = 0; b < sizes.size(); ++b) {
    params[b].assign(at[b], at[b] + sizes[b]);
    jac[b].assign(static_cast<size_t>(m * sizes[b]), 0.0);
    pp[b] = params[b].data();
    jp[b] = jac[b].data();
  }
  Eigen::VectorXd r(m);
  if (!cost.Evaluate(pp.data(), r.data(), jp.data())) {
    throw std::runtime_error(Where(__LINE__) + "cost function evaluation failed");
  }
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (size_t a = 0; a < sizes.size(); ++a) {
    const Eigen::Map<const RowMat> Ja(jac[a].data(), m, sizes[a]);
    g->segment(offsets[a], sizes[a]) += Ja.transpose() * r;
    for (size_t b = 0; b < sizes.size(); ++b) {
      const Eigen::Map<const RowMat> Jb(jac[b].data(), m, sizes[b]);
      H->block(offsets[a], offsets[b], sizes[a], sizes[b]) += Ja.transpose() * Jb;
    }
  }
}

template <int D>
TrajectoryEstimate SolveChain(
    const std::vector<std::unique_ptr<ceres::CostFunction>>& factors,
    const std::vector<std::vector<int>>& states, int num_states,
    const std::vector<int>& eval_states, const std::vector<int>& nodes,
    const std::vector<typename ChainSmoother<D>::Vector>* linearization = nullptr) {
  ChainSmoother<D> system(num_states);
  const std::vector<typename ChainSmoother<D>::Vector> x =
      linearization != nullptr ? *linearization
                               : std::vector<typename ChainSmoother<D>::Vector>(
                                     num_states, ChainSmoother<D>::Vector::Zero());
  for (size_t f = 0; f < factors.size(); ++f) system.AddFactor(*factors[f], states[f][0], x);
  std::vector<typename ChainSmoother<D>::Vector> delta;
  std::vector<typename ChainSmoother<D>::Block> cov;
  system.Solve(&delta, &cov);
  TrajectoryEstimate est;
  est.nodes = nodes;
  for (int s : eval_states) {
    est.mean.emplace_back(x[s] + delta[s]);
    est.covariance.emplace_back(cov[s]);
  }
  return est;
}

std::vector<int> PositionNodes(const Trajectory& traj) {
  std::vector<int> nodes;
  for (const auto& m : traj.position) nodes.push_back(m.node);
  return nodes;
}

}  // namespace

SensorModel MakeSensorModel(const DatasetConfig& dataset, const SensorConfig& sensors) {
  CheckSensorConfig(sensors);
  SensorModel m;
  for (const auto& a : sensors.accelerometers) {
    m.sigma_acc.push_back(a.sigma);
    m.rate_acc.push_back(a.rate_hz);
  }
  m.sigma_position = sensors.sigma_position;
  m.x0_mean = dataset.x0_mean;
  m.p0_variance = dataset.p0_variance;
  return m;
}

// ---- Estimator 1 ------------------------------------------------------------------------------

InputSchedule BuildInputSchedule(const Trajectory& traj) {
  CheckPositions(traj);
  struct Sample {
    int64_t t;
    double value;
    int sensor;
  };
  std::vector<Sample> samples;
  for (size_t s = 0; s < traj.accel.size(); ++s) {
    for (const auto& m : traj.accel[s]) {
      samples.push_back({traj.times_ns[m.node], m.value, static_cast<int>(s)});
    }
  }
  std::stable_sort(samples.begin(), samples.end(),
                   [](const Sample& a, const Sample& b) { return a.t < b.t; });
  if (samples.empty() || samples.front().t > traj.times_ns[0]) {
    throw std::invalid_argument(Where(__LINE__) +
                                "IMU as input needs an accelerometer sample at the first time");
  }
  // Stretches never exceed the nominal sample period (the smallest spacing of the merged
  // stream), so that a gap is covered by as many stretches as samples it lost (and a factor
  // always has >= 2 stretches, see ImuInputFactor).
  int64_t nominal = std::numeric_limits<int64_t>::max();
  for (size_t j = 1; j < samples.size(); ++j) {
    if (samples[j].t > samples[j - 1].t)
      nominal = std::min(nominal, samples[j].t - samples[j - 1].t);
  }
  InputSchedule schedule;
  size_t latest = 0;  // newest sample with t <= cur
  for (size_t i = 0; i + 1 < traj.position.size(); ++i) {
    const int64_t a = traj.times_ns[traj.position[i].node];
    const int64_t b = traj.times_ns[traj.position[i + 1].node];
    std::vector<HeldInput> stretches;
    int64_t cur = a;
    while (latest + 1 < samples.size() && samples[latest + 1].t <= cur) ++latest;
    while (cur < b) {
      int64_t next = latest + 1 < samples.size() ? std::min(b, samples[latest + 1].t) : b;
      if (nominal < b - cur) next = std::min(next, cur + nominal);
      const Sample& s = samples[latest];
      stretches.push_back({1e-9 * static_cast<double>(next - cur), s.value,
                           1e-9 * static_cast<double>(cur - s.t), s.sensor});
      cur = next;
      while (latest + 1 < samples.size() && samples[latest + 1].t <= cur) ++latest;
    }
    schedule.intervals.push_back(std::move(stretches));
  }
  return schedule;
}

ImuAsInput::ImuAsInput(const SensorModel& sensors, const InputHyperparameters& hyper)
    : sensors_(sensors), hyper_(hyper) {
  if (!(hyper.q_k > 0.0)) throw std::invalid_argument(Where(__LINE__) + "Q_k must be > 0");
  if (sensors.sigma_acc.empty()) throw std::invalid_argument(Where(__LINE__) + "no accelerometer");
  double total_rate = 0.0;
  for (double r : sensors.rate_acc) total_rate += r;
  const double dt = 1.0 / total_rate;
  const double s2 = sensors.sigma_acc[0] * sensors.sigma_acc[0];
  jerk_intensity_ = std::max(0.0, 3.0 * (hyper.q_k - s2) / dt);
}

double ImuAsInput::StretchVariance(const HeldInput& h) const {
  return hyper_.q_k + jerk_intensity_ * h.age;
}

std::vector<std::unique_ptr<ceres::CostFunction>> ImuAsInput::Factors(
    const Trajectory& traj, const InputSchedule& schedule,
    std::vector<std::vector<int>>* states) const {
  CheckPositions(traj);
  if (schedule.intervals.size() + 1 != traj.position.size()) {
    throw std::invalid_argument(Where(__LINE__) + "input schedule does not match the trajectory");
  }
  std::vector<std::unique_ptr<ceres::CostFunction>> factors;
  states->clear();
  const Eigen::Vector2d x0 = sensors_.x0_mean.head<2>();
  factors.push_back(std::make_unique<InitialStatePrior<2>>(
      x0, sensors_.p0_variance * Eigen::Matrix2d::Identity()));
  states->push_back({0});
  for (size_t i = 0; i < traj.position.size(); ++i) {
    factors.push_back(
        std::make_unique<ScalarMeasurement<2>>(0, traj.position[i].value, sensors_.sigma_position));
    states->push_back({static_cast<int>(i)});
    if (i + 1 < traj.position.size()) {
      ImuInputPreintegration pre;
      for (const auto& h : schedule.intervals[i]) {
        pre.Integrate({h.duration, h.input, StretchVariance(h)});
      }
      factors.push_back(std::make_unique<ImuInputFactor>(pre));
      states->push_back({static_cast<int>(i), static_cast<int>(i) + 1});
    }
  }
  return factors;
}

TrajectoryEstimate ImuAsInput::Smooth(const Trajectory& traj, const InputSchedule& schedule) const {
  std::vector<std::vector<int>> states;
  const auto factors = Factors(traj, schedule, &states);
  const int n = static_cast<int>(traj.position.size());
  std::vector<int> eval(n);
  for (int i = 0; i < n; ++i) eval[i] = i;
  return SolveChain<2>(factors, states, n, eval, PositionNodes(traj));
}

InputData SummarizeInputs(const Trajectory& traj, const InputSchedule& schedule) {
  CheckPositions(traj);
  if (schedule.intervals.size() + 1 != traj.position.size()) {
    throw std::invalid_argument(Where(__LINE__) + "input schedule does not match the trajectory");
  }
  InputData data;
  data.positions = traj.position;
  for (const auto& interval : schedule.intervals) {
    InputIntervalSummary s;
    for (const auto& h : interval) {
      // The recursion of ImuInputPreintegration::Integrate with the variance split in two:
      // x ← A x + B u, Σ ← A Σ Aᵀ + var·B Bᵀ, A = [[1, δ], [0, 1]], B = [δ²/2; δ].
      const double d = h.duration;
      Eigen::Matrix2d A;
      A << 1.0, d, 0.0, 1.0;
      const Eigen::Vector2d B(0.5 * d * d, d);
      s.delta_p += s.delta_v * d + 0.5 * h.input * d * d;
      s.delta_v += h.input * d;
      s.unit_covariance = A * s.unit_covariance * A.transpose() + B * B.transpose();
      s.age_covariance = A * s.age_covariance * A.transpose() + h.age * B * B.transpose();
      s.dt += d;
    }
    data.intervals.push_back(s);
  }
  return data;
}

double ImuAsInput::LogLikelihood(const Trajectory& traj, const InputSchedule& schedule) const {
  return LogLikelihood(SummarizeInputs(traj, schedule));
}

double ImuAsInput::LogLikelihood(const InputData& data) const {
  if (data.positions.empty() || data.intervals.size() + 1 != data.positions.size()) {
    throw std::invalid_argument(Where(__LINE__) + "input summaries do not match the positions");
  }
  Eigen::Vector2d x = sensors_.x0_mean.head<2>();
  Eigen::Matrix2d P = sensors_.p0_variance * Eigen::Matrix2d::Identity();
  const double r = sensors_.sigma_position * sensors_.sigma_position;
  double ll = ScalarUpdate<2>(0, data.positions[0].value, r, &x, &P);
  for (size_t i = 0; i < data.intervals.size(); ++i) {
    const InputIntervalSummary& s = data.intervals[i];
    Eigen::Matrix2d A;
    A << 1.0, s.dt, 0.0, 1.0;
    x = A * x + Eigen::Vector2d(s.delta_p, s.delta_v);
    P = A * P * A.transpose() + hyper_.q_k * s.unit_covariance + jerk_intensity_ * s.age_covariance;
    ll += ScalarUpdate<2>(0, data.positions[i + 1].value, r, &x, &P);
  }
  return ll;
}

// ---- Estimator 2 ------------------------------------------------------------------------------

ImuAsMeasurement::ImuAsMeasurement(const SensorModel& sensors, const PriorConfig& prior)
    : sensors_(sensors), prior_(prior) {
  if (!(prior.qc > 0.0) || !(prior.alpha >= 0.0)) {
    throw std::invalid_argument(Where(__LINE__) + "need sigma^2 > 0 and alpha >= 0");
  }
}

std::vector<std::unique_ptr<ceres::CostFunction>> ImuAsMeasurement::Factors(
    const Trajectory& traj, std::vector<std::vector<int>>* states) const {
  CheckPositions(traj);
  if (traj.accel.size() != sensors_.sigma_acc.size()) {
    throw std::invalid_argument(Where(__LINE__) + "accelerometer count differs from the model");
  }
  std::vector<std::unique_ptr<ceres::CostFunction>> factors;
  states->clear();
  factors.push_back(std::make_unique<InitialStatePrior<3>>(
      sensors_.x0_mean, sensors_.p0_variance * Eigen::Matrix3d::Identity()));
  states->push_back({0});
  const int n = static_cast<int>(traj.times_ns.size());
  for (int k = 0; k + 1 < n; ++k) {
    factors.push_back(MakeGpPriorFactor(prior_, traj.Time(k + 1) - traj.Time(k)));
    states->push_back({k, k + 1});
  }
  for (size_t s = 0; s < traj.accel.size(); ++s) {
    for (const auto& m : traj.accel[s]) {
      factors.push_back(std::make_unique<ScalarMeasurement<3>>(2, m.value, sensors_.sigma_acc[s]));
      states->push_back({m.node});
    }
  }
  for (const auto& m : traj.position) {
    factors.push_back(std::make_unique<ScalarMeasurement<3>>(0, m.value, sensors_.sigma_position));
    states->push_back({m.node});
  }
  return factors;
}

TrajectoryEstimate ImuAsMeasurement::Smooth(const Trajectory& traj) const {
  std::vector<std::vector<int>> states;
  const auto factors = Factors(traj, &states);
  const auto nodes = PositionNodes(traj);
  std::vector<Eigen::Vector3d> filtered;
  Filter(traj, &filtered);
  return SolveChain<3>(factors, states, static_cast<int>(traj.times_ns.size()), nodes, nodes,
                       &filtered);
}

TrajectoryEstimate ImuAsMeasurement::SmoothPreintegrated(const Trajectory& traj,
                                                         bool information_form) const {
  std::vector<std::vector<int>> states;
  const auto factors = Factors(traj, &states);
  const auto keys = PositionNodes(traj);
  const int n = static_cast<int>(traj.times_ns.size());
  if (keys.back() != n - 1) {
    throw std::invalid_argument(Where(__LINE__) + "the last grid time must be a position time");
  }
  const int num_keys = static_cast<int>(keys.size());
  std::vector<int> key_of(n, -1), interval_of(n, -1);
  for (int i = 0; i < num_keys; ++i) key_of[keys[i]] = i;
  for (int i = 0; i + 1 < num_keys; ++i) {
    for (int k = keys[i]; k < keys[i + 1]; ++k) interval_of[k] = i;
  }
  // Unary factors on a position-time state go to the chain; everything else to its interval.
  ChainSmoother<3> chain(num_keys);
  std::vector<Eigen::Vector3d> filtered;
  Filter(traj, &filtered);
  std::vector<Eigen::Vector3d> x_keys;
  for (int k : keys) x_keys.push_back(filtered[k]);
  std::vector<std::vector<size_t>> in_interval(num_keys > 1 ? num_keys - 1 : 0);
  for (size_t f = 0; f < factors.size(); ++f) {
    const auto& st = states[f];
    if (st.size() == 1 && key_of[st[0]] >= 0) {
      chain.AddFactor(*factors[f], key_of[st[0]], x_keys);
    } else {
      in_interval.at(interval_of[st[0]]).push_back(f);
    }
  }
  for (int i = 0; i + 1 < num_keys; ++i) {
    const int first = keys[i];
    const int local_states = keys[i + 1] - first + 1;
    if (!information_form) {
      ChainSmoother<3> local(local_states);
      const std::vector<Eigen::Vector3d> x(filtered.begin() + first,
                                           filtered.begin() + first + local_states);
      for (size_t f : in_interval[i]) local.AddFactor(*factors[f], states[f][0] - first, x);
      chain.AddPairRows(i, local.EliminateInterior());
      continue;
    }
    const int m = 3 * local_states;
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m);
    for (size_t f : in_interval[i]) {
      std::vector<int> offsets;
      std::vector<const double*> at;
      for (int s : states[f]) {
        offsets.push_back(3 * (s - first));
        at.push_back(filtered[s].data());
      }
      AddFactorDense(*factors[f], offsets, at, &H, &g);
    }
    std::vector<int> keep = {0, 1, 2, m - 3, m - 2, m - 1}, marginalize;
    for (int j = 3; j < m - 3; ++j) marginalize.push_back(j);
    const SchurComplementResult joint = SchurComplement(H, g, keep, marginalize);
    // The joint Gaussian factor ½δᵀH'δ + b'ᵀδ on (x_k, x_{k+1}) in square-root form.
    Eigen::MatrixXd A;
    Eigen::VectorXd r0;
    InformationSquareRoot(joint.information, joint.vector, &A, &r0);
    ChainSmoother<3>::Rows rows(A.rows(), 7);
    rows.leftCols<6>() = A;
    rows.col(6) = r0;
    chain.AddPairRows(i, rows);
  }
  std::vector<Eigen::Vector3d> delta;
  std::vector<Eigen::Matrix3d> cov;
  chain.Solve(&delta, &cov);
  TrajectoryEstimate est;
  est.nodes = keys;
  for (int i = 0; i < num_keys; ++i) {
    est.mean.emplace_back(x_keys[i] + delta[i]);
    est.covariance.emplace_back(cov[i]);
  }
  return est;
}

double ImuAsMeasurement::LogLikelihood(const Trajectory& traj) const {
  return Filter(traj, nullptr);
}

double ImuAsMeasurement::Filter(const Trajectory& traj,
                                std::vector<Eigen::Vector3d>* filtered) const {
  CheckPositions(traj);
  if (filtered != nullptr) filtered->resize(traj.times_ns.size());
  MotionModelCache cache(prior_);
  Eigen::Vector3d x = sensors_.x0_mean;
  Eigen::Matrix3d P = sensors_.p0_variance * Eigen::Matrix3d::Identity();
  std::vector<size_t> cursor(traj.accel.size(), 0);
  size_t pos_cursor = 0;
  const double rp = sensors_.sigma_position * sensors_.sigma_position;
  double ll = 0.0;
  const int n = static_cast<int>(traj.times_ns.size());
  for (int k = 0; k < n; ++k) {
    if (k > 0) {
      const DiscreteMotion& m = cache.Get(traj.times_ns[k] - traj.times_ns[k - 1]);
      x = m.transition * x;
      P = m.transition * P * m.transition.transpose() + m.covariance;
    }
    for (size_t s = 0; s < traj.accel.size(); ++s) {
      while (cursor[s] < traj.accel[s].size() && traj.accel[s][cursor[s]].node == k) {
        const double ra = sensors_.sigma_acc[s] * sensors_.sigma_acc[s];
        ll += ScalarUpdate<3>(2, traj.accel[s][cursor[s]].value, ra, &x, &P);
        ++cursor[s];
      }
    }
    while (pos_cursor < traj.position.size() && traj.position[pos_cursor].node == k) {
      ll += ScalarUpdate<3>(0, traj.position[pos_cursor].value, rp, &x, &P);
      ++pos_cursor;
    }
    if (filtered != nullptr) (*filtered)[k] = x;
  }
  return ll;
}

}  // namespace ctlio::study
