// Sensor models of the simulator (`ctlio_simulate --sensor NAME`, `--sim_sensor NAME` in
// ctlio_odometry --format sim and ctlio_experiment): the lidars and IMUs found on research robots
// in 2026, each with its datasheet geometry, rate, range and noise, its IMU, the lidar→IMU
// extrinsic of its usual mounting, and its ROS driver's conventions (driver_conventions.h: fields,
// per-point time, topics, frames, accelerometer unit), so that a simulated recording looks like
// the real sensor's. docs/user-guide/simulator.md lists them; data/sensors/<name>.yaml is each
// one's shipped odometry config.
//
// Spinning lidars: every beam of a column fires at the column's time (true for Ouster; Velodyne
// and Hesai fire their lasers a few µs apart within a 46–55 µs cycle, i.e. a pose error of at
// most speed × 55 µs, 0.8 mm at 15 m/s, which is not modelled). Beam elevations are the
// datasheets' tables (Velodyne, Hesai) or Ouster's uniform spacing.
//
// IMUs: per-sample σ = noise density × √rate. Ouster's internal ICM-20948 class IMU at 100 Hz
// (the Newer College preset's values); Livox's built-in BMI088 class IMU at 200 Hz
// (gyro 0.014 °/s/√Hz → 3.5e-3 rad/s, accel 175 µg/√Hz → 0.024 m/s²), published in g;
// an external tactical-grade MEMS IMU (Xsens MTi-300 class: gyro 0.01 °/s/√Hz, accel 60 µg/√Hz)
// for Velodyne and Hesai, 200 or 400 Hz.
#pragma once

#include <string>
#include <vector>

#include "ctlio/io/driver_conventions.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {

struct SensorModel {
  std::string name;         // "vlp16"
  std::string description;  // one line for `--sensor list`
  LidarConfig lidar;        // geometry, rate, ranges, noise (realism options off)
  // IMU rate, noise, bias walk and initial biases (the rest of ImuConfig at its defaults).
  double imu_rate_hz = 200.0;
  double accel_noise = 0.0, gyro_noise = 0.0;          // per sample
  double accel_bias_walk = 0.0, gyro_bias_walk = 0.0;  // per √s
  SE3 imu_from_lidar;                                  // T_imu_lidar of the usual mounting
  io::DriverConvention driver;                         // what its ROS driver writes
  // Its unit effects (sensor_effects.h), applied by the presets, not by ApplySensorModel.
  std::string effects_family;
};

// Every model, in the order `--sensor list` prints them: os0_128, os1_64, os1_128, vlp16,
// hdl32e, pandar_xt32, mid360, avia.
const std::vector<SensorModel>& SensorModels();
// The model of that name; throws std::runtime_error listing the names otherwise.
const SensorModel& FindSensorModel(const std::string& name);
// "name  description" lines, one per model.
std::string ListSensorModels();

// The model's lidar, IMU (rate, noise, bias walk; gravity, biases and realism options kept) and
// extrinsic applied to `config`; motion, world and duration kept.
void ApplySensorModel(const SensorModel& model, SimConfig* config);

}  // namespace ctlio::sim
