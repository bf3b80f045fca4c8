// The IMU sample (THE type: dataset readers in apps/io, the odometry and the factors all use it)
// and feeding a time interval of samples into a PreintegratedImu. Readers of sample files live in
// apps/io (e.g. ctlio/io/euroc.h).
//
// Time is int64 nanoseconds here (as in I/O, SPEC §1) and double seconds inside the factors.
#pragma once

#include <cstdint>
#include <vector>

#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

struct ImuSample {
  std::int64_t t_ns = 0;
  Vec3 gyro = Vec3::Zero();   // rad/s, sensor frame
  Vec3 accel = Vec3::Zero();  // m/s², specific force, sensor frame
  // Which IMU of the dataset took the sample (index into io::DataSource::Imus(); 0 with a single
  // IMU). Each IMU has its own clock grid, mounting, noise and biases.
  int imu = 0;
};

// Integrates the samples covering [t0_ns, t1_ns] with a zero-order hold (sample
// k holds on [t_k, t_{k+1})); partial first and last intervals are cut at t0, t1.
// Throws std::runtime_error if the samples do not cover the interval or a gap
// between samples exceeds max_gap_ns.
void IntegrateInterval(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                       std::int64_t t1_ns, PreintegratedImu* pim,
                       std::int64_t max_gap_ns = 50'000'000);

}  // namespace ctlio::imu
