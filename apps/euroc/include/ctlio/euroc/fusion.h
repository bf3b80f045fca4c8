// The estimators of the EuRoC fusion experiment (apps/euroc_fusion.cpp): the same noisy positions
// fused with the real IMU three ways, in batch, each a Ceres problem of library factors:
//   ImuAsInput        Forster preintegration between the position times (PreintegratedImuFactor,
//                     BiasRandomWalk, PositionMeasurement on T_wb);
//   ImuAsMeasurement  a WNOJ/Singer GP prior on SE(3) knots at the position times, every gyro and
//                     accelerometer sample a measurement of the interpolated state (SingerPrior,
//                     ImuGyroMeasurement, ImuAccelMeasurement, PositionMeasurement on T_rm);
//   PositionsOnly     a WNOJ prior on the 3-D position (VectorGpPrior, LinearMeasurement).
// Map = EuRoC world (z up), so C_mi = I, held constant.
#pragma once

#include <cstdint>
#include <vector>

#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/imu/imu_data.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/io/euroc.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::euroc {

inline constexpr double kGravity = 9.81;

// A noisy position measurement with the ground truth it was made from.
struct Position {
  std::int64_t t_ns = 0;
  Vec3 measured = Vec3::Zero();
  io::GroundTruthState truth;
};

// Shared IMU inputs of the IMU methods.
struct ImuNoiseModel {
  double accel_var = 0.0, gyro_var = 0.0;  // per sample, per axis
  Vec3 gyro_bias = Vec3::Zero();           // from the still start
  double sample_dt = 0.005;
  double accel_rw_psd = 3.0e-3 * 3.0e-3;  // imu0_sensor.yaml random walks
  double gyro_rw_psd = 1.9393e-5 * 1.9393e-5;
};

struct SolveOptions {
  double position_sigma = 0.05;  // m, std of each position axis
  int max_iterations = 200;      // Levenberg–Marquardt iterations per solve
  bool verbose = false;          // print the solver progress
  bool nees = false;             // position covariances by ceres::Covariance
  // Cauchy loss scale on the whitened accelerometer error (0 = no loss); with warm start the
  // problem is solved without the loss first, then with it from there.
  double cauchy_scale = 0.0;
  bool cauchy_warm_start = true;
};

struct Estimate {
  std::vector<Vec3> p;
  std::vector<Mat3> C_wb;  // empty for positions only
  std::vector<Vec3> v;     // world velocity (initialises the IMU methods)
  std::vector<Mat3> P;     // position covariance (empty without NEES)
  double seconds = 0.0;
};

struct Metrics {
  double pos_rmse = 0.0, rot_rmse_deg = 0.0, tilt_rmse_deg = 0.0, nees = 0.0;
  bool has_rotation = false, has_nees = false;
};

// Position and rotation RMSE against the ground truth at the knot times, tilt RMSE, position
// NEES (expected 3) where covariances are available.
Metrics Evaluate(const std::vector<Position>& segment, const Estimate& estimate);

// Ground truth subsampled every `stride` rows inside the IMU's time span, plus Gaussian noise.
std::vector<Position> NoisyPositions(const std::vector<io::GroundTruthState>& truth,
                                     const std::vector<imu::ImuSample>& imu, int stride,
                                     double sigma, unsigned seed);

// The positions with t in [t_first + from_s, t_first + from_s + length_s].
std::vector<Position> Slice(const std::vector<Position>& all, double from_s, double length_s);

// Accelerometer and gyro variances and the gyro bias from the still start [t_0, t_0 + 1 s).
ImuNoiseModel StillStartNoise(const std::vector<imu::ImuSample>& imu);

Estimate PositionsOnly(const std::vector<Position>& segment, double qc, const SolveOptions& o);

// Both IMU methods start from `init` (positions and velocities, e.g. PositionsOnly's), the
// attitude of the first knot from ground truth (yaw is unobservable from a still start) and
// gyro dead reckoning for the others.
Estimate ImuAsInput(const std::vector<imu::ImuSample>& imu, const std::vector<Position>& segment,
                    const ImuNoiseModel& noise, const Estimate& init, const SolveOptions& o);
Estimate ImuAsMeasurement(const std::vector<imu::ImuSample>& imu,
                          const std::vector<Position>& segment, const ImuNoiseModel& noise,
                          const Estimate& init, const gp::SingerModel<6>& model,
                          imu::AccelModel accel_model, const SolveOptions& o);

}  // namespace ctlio::euroc
