// What the simulated LIO tests share: the shipped simulation config, and the sequence the online
// calibration tests start wrong on.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "common/test_paths.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::testing {

// data/sim_lio.yaml, the config of the simulated experiments (docs/experiments), with the
// subsampling of the reduced sensors the tests simulate (16-32 beams, every 4th-8th firing): the
// shipped 0.8 m is tuned for the full-resolution sweep and leaves these sparse sweeps too few
// keypoints; 0.5 m is what the config's comment prescribes for them (and what the reduced-sensor
// tables of docs/experiments were measured with).
inline lio::OdometryConfig SimLioConfig() {
  lio::OdometryConfig config =
      lio::LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  // Also in the per-method configs (each a whole config, resolved when the file was read).
  const auto reduced = [](lio::OdometryConfig* c) {
    c->frontend.voxel_size = 0.5;
    c->frontend.initial_voxel_size = 0.5;
  };
  reduced(&config);
  for (auto& [method, method_config] : config.per_method) {
    auto copy = std::make_shared<lio::OdometryConfig>(*method_config);
    reduced(copy.get());
    method_config = std::move(copy);
  }
  return config;
}

// 1.5 s of `regime` at tuning index 100, 16 beams, every 8th firing: the knot-count tests'
// sequence (a fast one splits sweeps, a walk does not).
inline sim::SimConfig ShortSequenceAtIndex100(sim::Regime regime) {
  sim::SimConfig c = sim::ExperimentConfig(regime, 100);
  c.duration_s = 1.5;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  return c;
}

// A short sparse sequence for pipeline tests: 1 s of medium motion (index 0), 16 beams, every 8th
// firing: enough scans to fill and slide the window in a second or two of test time.
inline sim::SimConfig ShortSparseSequence() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = 1.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  return c;
}

// Tuning sequence `regime`/100 (not one of the reported indices 0–9 of docs/experiments) for
// `duration_s`, reduced lidar (16 beams, every 4th firing), with the calibration the tests start
// wrong from: a nominal extrinsic 3° / 10 cm off the truth (axis and direction drawn for index 100)
// and the IMU's stamps late by `imu_stamp_offset_s`.
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
