// The two estimators of the 1D study (SPEC §6), as full-trajectory smoothers built from Ceres
// cost functions, and their exact marginal likelihoods for training.
//
// Estimator 1, IMU as input: state [p, v] at the position-measurement times, accelerometer
// samples preintegrated into ImuInputFactor (zero-order hold, one input variance Q_k per sample
// interval), InitialStatePrior and position ScalarMeasurements. Dropout design (beyond the paper):
// the input model has nothing to say about the acceleration between samples, so through a gap the
// last sample is held and the input variance of a stretch starting `age` seconds after that
// sample is Q_k + q_j·age, with q_j = 3·(Q_k − σ_acc²)/Δt the jerk intensity implied by the
// WNOJ calibration Q_k = σ_acc² + q_j·Δt/3 (SPEC §6). It ignores that the held-input errors of
// consecutive stretches are correlated (it cannot represent them), so it is overconfident in long
// gaps — measured by the NEES over the gap. Several accelerometers are merged into one input
// stream by the same rule: every stretch holds the newest sample of any accelerometer.
//
// Estimator 2, IMU as measurement: state [p, v, a] at every sensor time, the GP prior (WNOJ/Singer
// with σ² = Qc, α) between consecutive states, every accelerometer sample and every position as a
// ScalarMeasurement. A dropout simply removes measurements; further accelerometers simply add
// theirs.
//
// Both problems are linear-Gaussian, so one Gauss-Newton step from any point is the exact
// solution, and the block-tridiagonal solver gives the exact marginal covariances.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "ctlio/study/imu_input_factor.h"
#include "ctlio/study/simulation.h"

namespace ctlio::study {

// Estimate at the evaluation times (the position-measurement times).
struct TrajectoryEstimate {
  std::vector<int> nodes;  // grid nodes of the evaluation times
  std::vector<Eigen::VectorXd> mean;
  std::vector<Eigen::MatrixXd> covariance;
};

// Known sensor noise and the initial-state prior, shared by both estimators.
struct SensorModel {
  std::vector<double> sigma_acc;  // per accelerometer
  std::vector<double> rate_acc;   // per accelerometer
  double sigma_position = 0.01;
  Eigen::Vector3d x0_mean = Eigen::Vector3d::Zero();
  double p0_variance = 1e-3;
};
SensorModel MakeSensorModel(const DatasetConfig& dataset, const SensorConfig& sensors);

// ---- Estimator 1: IMU as input --------------------------------------------------------------

// One zero-order-hold stretch before its variance is known: duration, held sample, its age at
// the start of the stretch, and the sensor it came from.
struct HeldInput {
  double duration;
  double input;
  double age;
  int sensor;
};

// Stretches between consecutive position times, built once per trajectory.
struct InputSchedule {
  std::vector<std::vector<HeldInput>> intervals;  // intervals[i]: position i → i + 1
};
InputSchedule BuildInputSchedule(const Trajectory& traj);

// One position interval of IMU as input, preintegrated once for every Q_k: the input enters
// the mean only, and the stretch variances Q_k + q_j·age enter the covariance linearly, so
//   Σ(Q_k) = Q_k·unit_covariance + q_j·age_covariance,
//   unit_covariance = Σ_j Φ(rest_j) B_j B_jᵀ Φ(rest_j)ᵀ, age_covariance = Σ_j age_j·(same term).
// A trajectory shrinks from thousands of stretches to one summary per position interval, which
// makes the likelihood of a large validation set cheap in time and memory (the positions carry
// little information about Q_k, so its maximum-likelihood fit needs ~1000 trajectories; see
// docs/experiments/study-1d.md).
struct InputIntervalSummary {
  double dt = 0.0;
  double delta_p = 0.0;
  double delta_v = 0.0;
  Eigen::Matrix2d unit_covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d age_covariance = Eigen::Matrix2d::Zero();
};
// Everything the IMU-as-input likelihood needs from one trajectory.
struct InputData {
  std::vector<Measurement> positions;
  std::vector<InputIntervalSummary> intervals;  // intervals[i]: position i → i + 1
};
InputData SummarizeInputs(const Trajectory& traj, const InputSchedule& schedule);

struct InputHyperparameters {
  double q_k = 0.00338;  // per-sample input variance (m²/s⁴)
};

class ImuAsInput {
 public:
  ImuAsInput(const SensorModel& sensors, const InputHyperparameters& hyper);
  // Variance of a stretch (see the file comment).
  double StretchVariance(const HeldInput& h) const;
  // Full-trajectory smoother with marginal covariances at the position times.
  TrajectoryEstimate Smooth(const Trajectory& traj, const InputSchedule& schedule) const;
  // log p(positions | accelerometer inputs) by a Kalman filter: the exact marginal likelihood of
  // the linear-Gaussian model (only the positions are measurements here).
  double LogLikelihood(const Trajectory& traj, const InputSchedule& schedule) const;
  // The same from the interval summaries (the two agree to round-off; tested).
  double LogLikelihood(const InputData& data) const;
  // The Ceres factors of the problem (for the cross-check against ceres::Solve).
  std::vector<std::unique_ptr<ceres::CostFunction>> Factors(
      const Trajectory& traj, const InputSchedule& schedule,
      std::vector<std::vector<int>>* states) const;

 private:
  SensorModel sensors_;
  InputHyperparameters hyper_;
  double jerk_intensity_;
};

// ---- Estimator 2: IMU as measurement --------------------------------------------------------

class ImuAsMeasurement {
 public:
  // The smoothers linearise at the Kalman-filter estimate: the problem is linear, so any point
  // gives the same solution in exact arithmetic, but starting close keeps the Gauss-Newton step
  // — and its round-off, which scales with it — small (≈ 1e-3 instead of the trajectory's 10 m).
  ImuAsMeasurement(const SensorModel& sensors, const PriorConfig& prior);
  TrajectoryEstimate Smooth(const Trajectory& traj) const;
  // Same estimate by heterogeneous preintegration (paper Fig. 2, eq. 26, SPEC §3): between each
  // pair of consecutive position times the in-between states and their measurements are
  // eliminated by a Schur complement into one joint Gaussian factor on the two end states; the
  // resulting chain of position-time states is then solved. By default the elimination is the
  // square-root (QR) Schur complement of ChainSmoother::EliminateInterior; information_form =
  // true uses the dense information-form SchurComplement of ctlio/solvers/schur_complement.h
  // instead (exact in exact arithmetic, but at 400 Hz the in-between information reaches 1e16
  // and it loses most digits — kept to measure that).
  TrajectoryEstimate SmoothPreintegrated(const Trajectory& traj,
                                         bool information_form = false) const;
  // log p(accelerometer samples, positions) by a Kalman filter.
  double LogLikelihood(const Trajectory& traj) const;
  std::vector<std::unique_ptr<ceres::CostFunction>> Factors(
      const Trajectory& traj, std::vector<std::vector<int>>* states) const;

 private:
  // Kalman filter: returns the log-likelihood and optionally the filtered mean at every node.
  double Filter(const Trajectory& traj, std::vector<Eigen::Vector3d>* filtered) const;

  SensorModel sensors_;
  PriorConfig prior_;
};

}  // namespace ctlio::study
