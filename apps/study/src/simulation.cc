#include "ctlio/study/simulation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "ctlio/study/motion.h"

namespace ctlio::study {
namespace {

std::string Where() { return std::string(__FILE__) + ": "; }

int64_t ToNs(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

}  // namespace

DatasetConfig WnojDataset() {
  DatasetConfig d;
  d.name = "wnoj";
  d.prior = PriorConfig{1.0, 0.0};
  d.x0_mean = Eigen::Vector3d(0.0, 0.0, 1.0);
  return d;
}

DatasetConfig SingerDataset() {
  DatasetConfig d;
  d.name = "singer";
  d.prior = PriorConfig{1.0, 10.0};
  d.x0_mean = Eigen::Vector3d(0.0, 1.0, 0.0);
  return d;
}

void CheckSensorConfig(const SensorConfig& s) {
  if (!(s.duration_s > 0.0)) throw std::invalid_argument(Where() + "duration_s must be > 0");
  if (s.accelerometers.empty()) throw std::invalid_argument(Where() + "need an accelerometer");
  for (const auto& a : s.accelerometers) {
    if (!(a.rate_hz > 0.0) || !(a.sigma > 0.0) || !(a.offset_s >= 0.0)) {
      throw std::invalid_argument(Where() + "accelerometer needs rate > 0, sigma > 0, offset >= 0");
    }
  }
  if (!(s.position_rate_hz > 0.0) || !(s.sigma_position > 0.0)) {
    throw std::invalid_argument(Where() + "positions need rate > 0 and sigma > 0");
  }
}

Trajectory Simulate(const DatasetConfig& dataset, const SensorConfig& sensors, uint64_t seed,
                    int set_id, int index) {
  CheckSensorConfig(sensors);
  const int64_t end_ns = ToNs(sensors.duration_s);
  // Sensor times in integer nanoseconds so that coinciding times merge exactly.
  // Dropped samples keep their node and their noise draw, so a dropout run differs from the
  // nominal one only by the missing samples.
  std::vector<std::vector<std::pair<int64_t, bool>>> accel_times(sensors.accelerometers.size());
  std::vector<int64_t> all;
  for (size_t s = 0; s < sensors.accelerometers.size(); ++s) {
    const auto& a = sensors.accelerometers[s];
    for (int64_t j = 0;; ++j) {
      const int64_t t = ToNs(a.offset_s + static_cast<double>(j) / a.rate_hz);
      if (t > end_ns) break;
      const bool dropped = sensors.dropout_end_s > sensors.dropout_start_s &&
                           t >= ToNs(sensors.dropout_start_s) && t < ToNs(sensors.dropout_end_s);
      accel_times[s].push_back({t, dropped});
      all.push_back(t);
    }
  }
  std::vector<int64_t> position_times;
  for (int64_t j = 0;; ++j) {
    const int64_t t = ToNs(static_cast<double>(j) / sensors.position_rate_hz);
    if (t > end_ns) break;
    position_times.push_back(t);
    all.push_back(t);
  }
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());

  Trajectory traj;
  traj.times_ns = all;
  auto node_of = [&](int64_t t) {
    return static_cast<int>(std::lower_bound(all.begin(), all.end(), t) - all.begin());
  };

  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32),
                    static_cast<uint32_t>(set_id), static_cast<uint32_t>(index)};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto draw3 = [&]() { return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)); };

  // Exact discretisation of the prior: x_{k+1} = Φ x_k + L w, L Lᵀ = Q(Δt) (SPEC §2).
  traj.truth.resize(all.size());
  traj.truth[0] = dataset.x0_mean + std::sqrt(dataset.p0_variance) * draw3();
  MotionModelCache cache(dataset.prior);
  for (size_t k = 0; k + 1 < all.size(); ++k) {
    const auto& m = cache.Get(all[k + 1] - all[k]);
    traj.truth[k + 1] = m.transition * traj.truth[k] + m.sqrt_covariance * draw3();
  }
  traj.accel.resize(sensors.accelerometers.size());
  for (size_t s = 0; s < sensors.accelerometers.size(); ++s) {
    for (const auto& [t, dropped] : accel_times[s]) {
      const int n = node_of(t);
      const double z = traj.truth[n][2] + sensors.accelerometers[s].sigma * normal(rng);
      if (!dropped) traj.accel[s].push_back({n, z});
    }
  }
  for (int64_t t : position_times) {
    const int n = node_of(t);
    traj.position.push_back({n, traj.truth[n][0] + sensors.sigma_position * normal(rng)});
  }
  return traj;
}

}  // namespace ctlio::study
