// Readers of the EuRoC MAV text files the IMU experiments use (SPEC §7: euroc_v1_01_easy): the
// ASL IMU CSV and OpenVINS' vicon2gt ground-truth CSV. Time is int64 nanoseconds (SPEC §1).
// Both throw std::runtime_error naming the file and the 1-based line of any malformed row (wrong
// field count, non-numeric or non-finite value, time not strictly increasing), or the file alone
// when it is missing or has no data rows.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/factors/imu/imu_data.h"
#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::io {

// EuRoC ASL imu0/data.csv: "t_ns,wx,wy,wz,ax,ay,az"; '#' lines are comments.
std::vector<imu::ImuSample> ReadEurocImuCsv(const std::string& path);

// A ground-truth navigation state with biases (OpenVINS vicon2gt CSV:
// "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz,bwx,bwy,bwz,bax,bay,baz"). The pose is IMU → world;
// bias = [b_a; b_g] as everywhere in ctlio.
struct GroundTruthState {
  std::int64_t t_ns = 0;
  imu::NavState x;
  Vec6 bias = Vec6::Zero();
};
std::vector<GroundTruthState> ReadVicon2gtCsv(const std::string& path);

}  // namespace ctlio::io
