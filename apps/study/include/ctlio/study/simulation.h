// Ground truth and sensor simulation of the 1D study (SPEC §6): trajectories drawn from the
// WNOJ or Singer prior, accelerometers (any number, each with rate, time offset, noise) and
// position measurements. Time keys are int64 nanoseconds (SPEC §1); every sensor time is a
// node of the trajectory's time grid, so the truth is known exactly at every measurement.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

namespace ctlio::study {

// The motion prior per axis: ȧ = −α·a + w, w ~ GP(0, Qc·δ) (α = 0: WNOJ), SPEC §2.
struct PriorConfig {
  double qc = 1.0;     // σ² in the paper
  double alpha = 0.0;  // 0 → WNOJ
};

struct DatasetConfig {
  std::string name;
  PriorConfig prior;
  Eigen::Vector3d x0_mean = Eigen::Vector3d::Zero();  // [p, v, a]
  double p0_variance = 1e-3;                          // P0 = p0_variance · I
};
DatasetConfig WnojDataset();    // Qc = 1, x0 = [0, 0, 1], P0 = diag(1e-3)
DatasetConfig SingerDataset();  // α = 10, Qc = 1, x0 = [0, 1, 0], P0 = diag(1e-3)

struct AccelerometerConfig {
  double rate_hz = 400.0;
  double offset_s = 0.0;  // first sample time
  double sigma = 0.05;    // m/s²
};

struct SensorConfig {
  double duration_s = 10.0;
  std::vector<AccelerometerConfig> accelerometers{AccelerometerConfig{}};
  double position_rate_hz = 10.0;
  double sigma_position = 0.01;  // m
  // Accelerometer dropout: every accelerometer is silent for t in [start, end) (none if end <=
  // start).
  double dropout_start_s = 0.0;
  double dropout_end_s = 0.0;
};

struct Measurement {
  int node;  // index into Trajectory::times
  double value;
};

struct Trajectory {
  std::vector<int64_t> times_ns;                // sorted union of every sensor time
  std::vector<Eigen::Vector3d> truth;           // [p, v, a] at each time
  std::vector<std::vector<Measurement>> accel;  // per accelerometer
  std::vector<Measurement> position;            // first at t = 0
  double Time(int node) const { return 1e-9 * static_cast<double>(times_ns[node]); }
};

// Draws trajectory `index` of a set; the random stream depends only on (seed, set_id, index), so
// any subset can be regenerated in any order or thread.
Trajectory Simulate(const DatasetConfig& dataset, const SensorConfig& sensors, uint64_t seed,
                    int set_id, int index);

// Validates a sensor configuration; throws std::invalid_argument naming the bad field.
void CheckSensorConfig(const SensorConfig& sensors);

}  // namespace ctlio::study
