#include "ctlio/solvers/lio/input_checks.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ctlio::lio {

void InputCheckOptions::Validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("input: " + what);
  };
  require(max_gyro > 0 && std::isfinite(max_gyro), "max_gyro must be positive and finite");
  require(max_accel > 0 && std::isfinite(max_accel), "max_accel must be positive and finite");
  require(gravity_tolerance > 0 && gravity_tolerance < 1, "gravity_tolerance must be in (0, 1)");
  require(constant_imu_duration > 0 && std::isfinite(constant_imu_duration),
          "constant_imu_duration must be positive and finite");
  require(moving_translation >= 0 && std::isfinite(moving_translation),
          "moving_translation must be >= 0 and finite");
  require(moving_rotation >= 0 && std::isfinite(moving_rotation),
          "moving_rotation must be >= 0 and finite");
  require(scan_time_tolerance >= 0 && scan_time_tolerance < 1e3,
          "scan_time_tolerance must be in [0, 1000) s");
  require(max_imu_gap_error >= 0 && max_imu_gap_error < 1e6,
          "max_imu_gap_error must be in [0, 1e6) s (0 = off)");
  require(accel_scale > 0 && std::isfinite(accel_scale),
          "accel_scale must be positive and finite (9.80665 for an IMU reporting g)");
}

std::optional<std::string> CheckImuRange(const ImuSample& s, const InputCheckOptions& o) {
  if (!s.gyro.allFinite() || !s.accel.allFinite()) return std::string("not finite");
  const double w = s.gyro.norm(), f = s.accel.norm();
  std::ostringstream m;
  if (!(w <= o.max_gyro)) {
    m << "|gyro| " << w << " rad/s beyond the physical range " << o.max_gyro
      << " rad/s (input.max_gyro)";
    return m.str();
  }
  if (!(f <= o.max_accel)) {
    m << "|accel| " << f << " m/s² beyond the physical range " << o.max_accel
      << " m/s² (input.max_accel)";
    return m.str();
  }
  return std::nullopt;
}

void ConstantImuDetector::Add(const ImuSample& s) {
  if (!have_ || s.gyro != last_.gyro || s.accel != last_.accel) first_ = s;
  last_ = s;
  have_ = true;
}

double ConstantImuDetector::ConstantSeconds() const {
  return have_ ? 1e-9 * double(last_.t_ns - first_.t_ns) : 0.0;
}

std::optional<std::string> CheckGravityMagnitude(const std::vector<ImuSample>& samples,
                                                 double gravity, double tolerance) {
  if (samples.empty()) return std::string("no IMU samples to check gravity against");
  Vec3 mean = Vec3::Zero();
  for (const ImuSample& s : samples) mean += s.accel;
  mean /= double(samples.size());
  const double g = mean.norm();
  if (std::abs(g - gravity) <= tolerance * gravity) return std::nullopt;
  std::ostringstream m;
  m << "mean specific force " << g << " m/s² over the first " << samples.size()
    << " IMU samples is not the configured gravity " << gravity << " m/s² (±" << 100 * tolerance
    << " %): ";
  // A reading in g is about 1/9.81 of gravity: a units error. Any other magnitude is as likely a
  // platform that accelerates in the window (not at rest, or a window misplaced by scan times
  // that overlap) as wrong units or axes; both are named, the motion first.
  if (std::abs(g * 9.80665 / gravity - 1.0) <= tolerance) {
    m << "accelerometer units or axes cannot be right (it reads about 1: g, not m/s²?)";
  } else {
    m << "the platform accelerates in the window (not at rest at the start, or the scan times "
         "put the window elsewhere), or the accelerometer units or axes are wrong";
  }
  return m.str();
}

size_t DropPointsOutside(int64_t lo_ns, int64_t hi_ns, LidarScan* scan) {
  size_t kept = 0;
  const size_t n = scan->points.size();
  for (size_t i = 0; i < n; ++i) {
    if (scan->times_ns[i] < lo_ns || scan->times_ns[i] > hi_ns) continue;
    scan->points[kept] = scan->points[i];
    scan->times_ns[kept] = scan->times_ns[i];
    ++kept;
  }
  scan->points.resize(kept);
  scan->times_ns.resize(kept);
  return n - kept;
}

bool PoseMoved(const SE3& a, const SE3& b, const InputCheckOptions& o) {
  const SE3 d = a.Inverse() * b;
  return d.translation().norm() > o.moving_translation ||
         Eigen::AngleAxisd(d.quaternion()).angle() > o.moving_rotation;
}

}  // namespace ctlio::lio
