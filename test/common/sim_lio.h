// What the simulated LIO tests share: the shipped simulation config, and the sequence the online
// calibration tests start wrong on.
#pragma once

#include <string>

#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::testing {

// data/sim_lio.yaml, the config of the simulated experiments (README).
inline lio::OdometryConfig SimLioConfig() {
  return lio::LoadOdometryConfig(std::string(CTLIO_SOURCE_DIR) + "/data/sim_lio.yaml");
}

// Tuning sequence `regime`/100 (not one of the README's reported indices 0–9) for `duration_s`,
// reduced lidar (16 beams, every 4th firing), with the calibration the tests start wrong from:
// a nominal extrinsic 3° / 10 cm off the truth (axis and direction drawn for index 100) and the
// IMU's stamps late by `imu_stamp_offset_s`.
inline sim::SimConfig WrongCalibrationSequence(sim::Regime regime, double duration_s,
                                               double imu_stamp_offset_s) {
  sim::SimConfig c = sim::ExperimentConfig(regime, 100);
  c.duration_s = duration_s;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 4;
  c.imu.stamp_offset_s = imu_stamp_offset_s;
  c.nominal_imu_from_lidar = sim::NominalExtrinsic(
      c.imu_from_lidar, sim::ParseExtrinsicError("3deg,0.10m"), sim::kExperimentSeed, 100);
  return c;
}

}  // namespace ctlio::testing
