// PredictKnotWithImu (imu_knot_prediction.h), the starting value of a new GP knot: carried from
// the true state at t0 through the simulator's noise-free IMU readings (its own kinematics,
// lidar_inertial_sim.cc, not the factor's), it lands on the true state at t0 + Δt, far nearer
// than the constant-velocity guess, at the motion start (an acceleration step from rest) and in
// the middle of medium and fast sequences, for an IMU in the robot frame and for a rotated IMU
// on a lever arm, with biases; without samples it is the constant-velocity guess; without an
// accelerometer ϖ_v is held. In the odometry (window.imu_prediction) it takes the motion start
// of a sequence from a few centimetres of error to under one.
#include "ctlio/solvers/lio/imu_knot_prediction.h"

#include <gtest/gtest.h>

#include <vector>

#include "common/sim_gp_state.h"
#include "common/test_paths.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

using ctlio::testing::TrueState;

// The IMU's readings at 200 Hz in (t0, t1], plus the bias.
std::vector<TimedImuSample> Samples(const sim::LidarInertialSim& sim, double t0, double t1,
                                    const SE3& body_from_imu, const Vec6& bias) {
  std::vector<TimedImuSample> out;
  for (int k = static_cast<int>(t0 * 200.0) + 1; k * 0.005 <= t1 + 1e-12; ++k) {
    const io::ImuSample s = sim.TrueImu(k * 0.005, body_from_imu);
    out.push_back({k * 0.005, s.gyro + bias.tail<3>(), s.accel + bias.head<3>()});
  }
  return out;
}

struct Errors {
  double position = 0.0;      // m
  double rotation = 0.0;      // rad
  double velocity = 0.0;      // m/s, linear part of ϖ
  double acceleration = 0.0;  // m/s², linear part of ϖ̇
};

Errors Compare(const gp::KnotState& a, const gp::KnotState& b) {
  const SE3 d = a.pose.Inverse() * b.pose;
  return {(a.pose.Inverse().translation() - b.pose.Inverse().translation()).norm(),
          d.Log().tail<3>().norm(), (a.velocity - b.velocity).head<3>().norm(),
          (a.acceleration - b.acceleration).head<3>().norm()};
}

gp::KnotState ConstantVelocity(const gp::KnotState& x, double dt) {
  return {SE3::Exp(dt * x.velocity) * x.pose, x.velocity, Vec6::Zero()};
}

TEST(ImuKnotPrediction, LandsOnTheSimulatedMotion) {
  const Vec6 bias = (Vec6() << 0.05, -0.03, 0.04, 0.01, -0.02, 0.015).finished();
  const SE3 rotated_on_arm = SE3::Exp((Vec6() << 0.3, -0.1, 0.05, 0.2, -0.4, 1.5).finished());
  for (const sim::Regime regime : {sim::Regime::kMedium, sim::Regime::kFast}) {
    sim::SimConfig config = sim::ExperimentConfig(regime, 100);
    config.duration_s = 4.0;
    const sim::LidarInertialSim sim(config);
    for (const SE3& body_from_imu : {SE3(), rotated_on_arm}) {
      ImuPredictionModel model;
      model.mounting = imu::ImuMounting::FromPose(body_from_imu);
      for (const double t0 : {0.2, 1.05, 2.3, 3.45}) {
        for (const double dt : {0.05, 0.1}) {
          const gp::KnotState start = TrueState(sim, t0), truth = TrueState(sim, t0 + dt);
          const gp::KnotState predicted =
              PredictKnotWithImu(start, t0, t0 + dt, Samples(sim, t0, t0 + dt, body_from_imu, bias),
                                 bias, Mat3::Identity(), model);
          const Errors e = Compare(predicted, truth);
          const Errors cv = Compare(ConstantVelocity(start, dt), truth);
          SCOPED_TRACE(::testing::Message()
                       << sim::RegimeName(regime) << " t0 " << t0 << " dt " << dt << " lever "
                       << body_from_imu.translation().norm());
          // Second order in the 5 ms sample spacing: under a millimetre and 2 cm/s, where the
          // fast regime reaches ~30 m/s² and ~100 rad/s².
          EXPECT_LT(e.position, 1e-3);
          EXPECT_LT(e.rotation, 1e-3);
          EXPECT_LT(e.velocity, 0.02);
          // ϖ̇_v is the last sample's (held for the rest of the interval, at most 5 ms).
          EXPECT_LT(e.acceleration, 0.6);
          // The constant-velocity guess misses by centimetres (the acceleration step at t0 =
          // 0.2: ½·a·Δt², a ~ 5–30 m/s²).
          EXPECT_GT(cv.position, 10.0 * e.position);
          EXPECT_GT(cv.acceleration, 2.0);
        }
      }
    }
  }
}

TEST(ImuKnotPrediction, WithoutSamplesIsTheConstantVelocityGuess) {
  gp::KnotState x;
  x.pose = SE3::Exp((Vec6() << 1, 2, 3, 0.1, -0.2, 0.3).finished());
  x.velocity << 0.5, -0.2, 0.1, 0.3, 0.1, -0.4;
  x.acceleration << 3, 2, 1, 0.5, 0.4, 0.3;
  const gp::KnotState p = PredictKnotWithImu(x, 1.0, 1.1, {}, Vec6::Zero(), Mat3::Identity(), {});
  const gp::KnotState cv = ConstantVelocity(x, 0.1);
  EXPECT_LT((p.pose.Log() - cv.pose.Log()).norm(), 1e-12);
  EXPECT_EQ(p.velocity, x.velocity);
  EXPECT_EQ(p.acceleration, Vec6::Zero());
}

TEST(ImuKnotPrediction, WithoutAnAccelerometerTheLinearVelocityIsHeld) {
  sim::SimConfig config = sim::ExperimentConfig(sim::Regime::kFast, 100);
  config.duration_s = 2.0;
  const sim::LidarInertialSim sim(config);
  const double t0 = 1.3, dt = 0.1;
  const gp::KnotState start = TrueState(sim, t0), truth = TrueState(sim, t0 + dt);
  ImuPredictionModel model;
  model.has_accelerometer = false;
  const gp::KnotState p =
      PredictKnotWithImu(start, t0, t0 + dt, Samples(sim, t0, t0 + dt, SE3(), Vec6::Zero()),
                         Vec6::Zero(), Mat3::Identity(), model);
  EXPECT_EQ(p.velocity.head<3>(), start.velocity.head<3>());
  EXPECT_EQ(p.acceleration.head<3>(), Vec3::Zero());
  // The rotation from the gyro alone.
  EXPECT_LT(Compare(p, truth).rotation, 2e-4);
  EXPECT_LT((p.velocity.tail<3>() - truth.velocity.tail<3>()).norm(), 1e-9);
}

// The motion start of medium/100 (SPEC §6: from rest, an acceleration step of ~7 m/s² at
// 0.2 s) with the calibration configuration (data/sim_lio_calibration.yaml, the true calibration
// configured): with the constant-velocity guess the Cauchy loss on the accelerometer all but
// switches off the sweep's samples and the first moving scan is ~2 cm off; started from the IMU
// it is under 1 cm.
TEST(ImuKnotPrediction, TheOdometryFollowsTheMotionStart) {
  OdometryConfig config =
      LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio_calibration.yaml");
  config.calibration = CalibrationOptions();
  ASSERT_TRUE(config.imu_prediction);  // the calibration configuration starts from the IMU
  sim::SimConfig sequence = sim::ExperimentConfig(sim::Regime::kMedium, 100);
  sequence.duration_s = 1.0;
  sequence.lidar.beams = 16;
  sequence.lidar.firing_decimation = 4;
  double rmse[2] = {0.0, 0.0}, max[2] = {0.0, 0.0};
  for (const bool predict : {false, true}) {
    config.imu_prediction = predict;
    sim::SimulatedSource source(sequence);
    const lioapp::RunSummary run = lioapp::RunOdometry(source, config);
    ASSERT_EQ(run.failed, 0) << run.first_failure;
    ASSERT_TRUE(run.ate.has_value());
    rmse[predict] = run.ate->rmse;
    max[predict] = run.ate->max;
  }
  // Measured: 1.9 cm → 0.6 cm at the worst scan, 0.75 → 0.41 cm RMSE.
  EXPECT_LT(max[1], 0.01);
  EXPECT_LT(max[1], 0.5 * max[0]);
  EXPECT_LT(rmse[1], 0.7 * rmse[0]);
}

}  // namespace
}  // namespace ctlio::lio
