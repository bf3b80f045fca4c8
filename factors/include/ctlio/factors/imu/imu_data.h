// IMU samples, the two EuRoC text formats the IMU work reads, and feeding a
// time interval of samples into a PreintegratedImu.
//
// Time is int64 nanoseconds here (I/O, SPEC §1) and double seconds inside the
// factors. Readers throw std::runtime_error naming the file and the 1-based
// line of any malformed row (wrong field count, non-numeric or non-finite
// value, time not strictly increasing).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

struct ImuSample {
  std::int64_t t_ns = 0;
  Vec3 gyro = Vec3::Zero();   // rad/s, sensor frame
  Vec3 accel = Vec3::Zero();  // m/s², specific force, sensor frame
};

// EuRoC ASL imu0/data.csv: "t_ns,wx,wy,wz,ax,ay,az"; '#' lines are comments.
std::vector<ImuSample> ReadEurocImuCsv(const std::string& path);

// A ground-truth navigation state with biases (OpenVINS vicon2gt CSV:
// "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz,bwx,bwy,bwz,bax,bay,baz"). The pose is
// IMU → world; bias = [b_a; b_g] as everywhere in ctlio.
struct GroundTruthState {
  std::int64_t t_ns = 0;
  NavState x;
  Vec6 bias = Vec6::Zero();
};
std::vector<GroundTruthState> ReadVicon2gtCsv(const std::string& path);

// Integrates the samples covering [t0_ns, t1_ns] with a zero-order hold (sample
// k holds on [t_k, t_{k+1})); partial first and last intervals are cut at t0, t1.
// Throws std::runtime_error if the samples do not cover the interval or a gap
// between samples exceeds max_gap_ns.
void IntegrateInterval(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                       std::int64_t t1_ns, PreintegratedImu* pim,
                       std::int64_t max_gap_ns = 50'000'000);

}  // namespace ctlio::imu
