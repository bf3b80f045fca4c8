// Further simulated IMUs from a one-line text (`--sim_imus` of ctlio_odometry and ctlio_simulate,
// `--imus` of ctlio_experiment): IMUs separated by ';', each a comma-separated list of key=value
// applied onto the first IMU's configuration (so gravity, the accelerometer model and the realism
// options are shared unless set):
//   rate=400             samples per second
//   xyz=0.3:0:0          lever arm: the IMU origin in the body frame [m]
//   rpy=0:0:90           IMU frame rotation about the body's x, y, z (C = Rz·Ry·Rx) [deg]
//   offset=0.0013        clock start: first sample this long after the sequence start [s]
//   stamp_offset=0.02    stamps δ early: the sample of the motion at t is stamped t − δ [s]
//                        (ImuConfig::stamp_offset_s; the odometry's time-offset calibration)
//   accel_noise=0.04     σ per sample [m/s²];  gyro_noise=0.02  [rad/s]
//   accel_bias=0.1       constant on every axis, or x:y:z [m/s²];  gyro_bias=... [rad/s]
//   outage=9:2           no samples in [9 s, 11 s); several joined by '+' (3:0.5+9:2)
// e.g. "rate=400,xyz=0.3:0:0,offset=0.0013,accel_noise=0.04,gyro_noise=0.02".
#pragma once

#include <string>
#include <vector>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {

// Throws std::runtime_error naming the IMU and the key on malformed text; "" gives none.
std::vector<ImuConfig> ParseImuSpecs(const std::string& text, const ImuConfig& first);

}  // namespace ctlio::sim
