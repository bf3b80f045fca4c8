// The IMU samples the odometry has received and not yet consumed (SPEC §3, §4): the single entry
// point for IMU data (AddImu checks order and applies the input gates of input_checks.h: range,
// finiteness, how long the output has stayed constant), the samples and the zero-order-hold
// signal over an interval, the longest hole in the stream, and trimming of what is no longer
// needed. With several IMUs (ImuSample::imu) each has its own stream, checked and queried on its
// own: their clocks are independent. Times are int64 ns at the interface and double seconds
// relative to the odometry's origin (the first scan's start) inside.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/input_checks.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// One piece of the zero-order-hold IMU signal: sample held constant for dt seconds.
struct ImuSegment {
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
  double t_begin = 0.0;  // seconds (odometry time)
  double dt = 0.0;
};

class ImuBuffer {
 public:
  explicit ImuBuffer(const InputCheckOptions& checks = {}) : checks_(checks) {}

  // Throws std::invalid_argument if the sample is older than the previous one of its IMU (or its
  // IMU index is outside [0, kMaxImus)); a repeated timestamp is dropped (the first sample is
  // kept) and counted in duplicates(). A sample that cannot be physical (not finite, or beyond
  // input.max_gyro / max_accel) is rejected: not stored, counted in rejected() and in
  // TakeRejections(); returns false then.
  bool AddImu(const ImuSample& sample);
  static constexpr int kMaxImus = 5;  // KnotKeys has bias ids for five IMUs

  // Samples rejected since the previous call, and the reason of the first of them.
  struct Rejections {
    size_t count = 0;
    std::string first;  // "IMU sample at <t> s rejected: <reason>"
  };
  Rejections TakeRejections();
  // How long the accepted output of an IMU has stayed bit-identical, up to its newest sample [s];
  // the longest over the IMUs (one frozen IMU among several is still a fault).
  double ConstantSeconds() const;

  // Odometry time: seconds since origin_ns (set once, at the first scan).
  void SetOrigin(int64_t origin_ns) { origin_ns_ = origin_ns; }
  int64_t origin_ns() const { return origin_ns_; }
  double Seconds(int64_t t_ns) const { return 1e-9 * static_cast<double>(t_ns - origin_ns_); }

  // The zero-order-hold signal of IMU `imu` over [t_a, t_b] (seconds); the sample in force at t_a
  // is the last one at or before t_a (or the first one if none). Returns the longest hole between
  // consecutive samples inside [t_a, t_b] (including the ends) in *max_gap (may be null).
  std::vector<ImuSegment> Segments(double t_a, double t_b, double* max_gap, int imu = 0) const;
  // The longest hole in IMU `imu`'s stream over [t_a, t_b], as Segments reports it.
  double MaxGap(double t_a, double t_b, int imu = 0) const;
  // All samples of IMU `imu` with t_a < t ≤ t_b.
  std::vector<ImuSample> Samples(double t_a, double t_b, int imu = 0) const;
  // Drops samples that can no longer be needed (older than t minus one sample), in every stream.
  void Trim(double t);

  // IMU `imu`'s samples (empty if none has arrived); the number of streams (1 + highest index).
  const std::deque<ImuSample>& samples(int imu = 0) const;
  int num_imus() const { return static_cast<int>(streams_.size()); }
  size_t duplicates() const { return duplicates_; }
  size_t rejected() const { return rejected_; }

 private:
  InputCheckOptions checks_;
  std::vector<std::deque<ImuSample>> streams_ = std::vector<std::deque<ImuSample>>(1);
  size_t duplicates_ = 0;
  size_t rejected_ = 0;
  Rejections pending_;
  std::vector<ConstantImuDetector> constant_ = std::vector<ConstantImuDetector>(1);  // per IMU
  int64_t origin_ns_ = 0;
};

}  // namespace ctlio::lio
