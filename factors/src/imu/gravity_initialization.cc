#include "ctlio/factors/imu/gravity_initialization.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ctlio::imu {

GravityInitialization InitializeGravity(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                                        std::int64_t duration_ns,
                                        const GravityInitializationOptions& options,
                                        const Mat3& C_body_sensor) {
  if (!(options.block_ns > 0) || !(duration_ns > 0)) {
    throw std::invalid_argument("InitializeGravity: duration and block length must be > 0");
  }
  GravityInitialization out;
  const std::int64_t t1_ns = t0_ns + duration_ns;
  // Half-open window [t0, t1).
  const auto inside = [&](const ImuSample& s) { return s.t_ns >= t0_ns && s.t_ns < t1_ns; };
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (const ImuSample& s : samples) {
    if (!inside(s)) continue;
    sum += C_body_sensor * (s.accel - options.accel_bias);
    ++n;
  }
  if (n < options.min_samples) {
    std::ostringstream msg;
    msg << "InitializeGravity: only " << n << " IMU samples in [" << t0_ns << ", " << t1_ns
        << "] ns (need " << options.min_samples << ")";
    throw std::runtime_error(msg.str());
  }
  out.mean_accel = sum / n;

  // Raw scatter and block means.
  double sq = 0.0;
  Vec3 block_f = Vec3::Zero(), block_w = Vec3::Zero();
  int block_n = 0;
  std::int64_t block_end = t0_ns + options.block_ns, block_first = 0, block_last = 0;
  const auto close_block = [&]() {
    // A block spanning less than half its length (the window's tail) averages
    // too few samples to tell motion from vibration: skip it.
    const bool usable = block_n > 0 && 2 * (block_last - block_first) >= options.block_ns;
    if (!usable) {
      block_f.setZero();
      block_w.setZero();
      block_n = 0;
      return;
    }
    out.max_block_accel_deviation =
        std::max(out.max_block_accel_deviation, (block_f / block_n - out.mean_accel).norm());
    out.max_block_gyro_rate = std::max(out.max_block_gyro_rate, (block_w / block_n).norm());
    block_f.setZero();
    block_w.setZero();
    block_n = 0;
  };
  for (const ImuSample& s : samples) {
    if (!inside(s)) continue;
    while (s.t_ns >= block_end) {
      close_block();
      block_end += options.block_ns;
    }
    if (block_n == 0) block_first = s.t_ns;
    block_last = s.t_ns;
    const Vec3 f = C_body_sensor * (s.accel - options.accel_bias);
    sq += (f - out.mean_accel).squaredNorm();
    block_f += f;
    block_w += C_body_sensor * s.gyro;
    ++block_n;
  }
  close_block();
  out.accel_std = std::sqrt(sq / n);

  std::ostringstream why;
  if (out.max_block_accel_deviation > options.max_block_accel_deviation) {
    why << " block-mean specific force deviates by " << out.max_block_accel_deviation << " m/s² > "
        << options.max_block_accel_deviation << ";";
  }
  if (out.max_block_gyro_rate > options.max_block_gyro_rate) {
    why << " block-mean gyro rate " << out.max_block_gyro_rate << " rad/s > "
        << options.max_block_gyro_rate << ";";
  }
  if (out.accel_std > options.max_accel_std) {
    why << " accelerometer scatter " << out.accel_std << " m/s² > " << options.max_accel_std << ";";
  }
  const double g_error = std::abs(out.mean_accel.norm() - options.gravity);
  if (g_error > options.max_gravity_error) {
    why << " |mean specific force| " << out.mean_accel.norm()
        << " differs from g = " << options.gravity << " by " << g_error << " m/s² > "
        << options.max_gravity_error << ";";
  }
  if (!why.str().empty()) {
    throw std::runtime_error("InitializeGravity: platform not still over [" +
                             std::to_string(t0_ns) + ", " + std::to_string(t1_ns) +
                             "] ns:" + why.str());
  }

  const Vec3& f = out.mean_accel;
  out.roll = std::atan2(f.y(), f.z());
  out.pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  const Mat3 C_im = so3::Exp(Vec3(0.0, out.pitch, 0.0)) * so3::Exp(Vec3(out.roll, 0.0, 0.0));
  out.C_mi = C_im.transpose();
  return out;
}

double TiltError(const Mat3& C_mi, const Mat3& C_wb_truth) {
  // Up in the robot frame: C_mi e_z (map = robot frame at start) and C_wbᵀ e_z.
  const Vec3 a = C_mi * Vec3::UnitZ();
  const Vec3 b = C_wb_truth.transpose() * Vec3::UnitZ();
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Vec3 TiltErrorVector(const Mat3& C_mi, const Mat3& C_wb_truth) {
  // Estimated up direction (robot frame) mapped to the world with the true attitude; the
  // rotation about w × e_z that takes it to e_z is C_est C_wbᵀ.
  const Vec3 w = C_wb_truth * (C_mi * Vec3::UnitZ());
  const Vec3 axis = w.cross(Vec3::UnitZ());
  const double s = axis.norm();
  if (s == 0.0) {  // exact, or upside down (then any horizontal axis is a smallest rotation)
    return w.z() > 0.0 ? Vec3::Zero() : Vec3(std::acos(-1.0), 0.0, 0.0);
  }
  return axis * (std::atan2(s, w.z()) / s);
}

void RollPitch(const Mat3& C_wb, double* roll, double* pitch) {
  // Third row of R_z R_y R_x = [−sinθ, sinφ cosθ, cosφ cosθ].
  *pitch = std::asin(std::clamp(-C_wb(2, 0), -1.0, 1.0));
  *roll = std::atan2(C_wb(2, 1), C_wb(2, 2));
}

}  // namespace ctlio::imu
