#include "ctlio/solvers/lio/input_checks.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "ctlio/solvers/lio/yaml_io.h"

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
}

InputCheckOptions TakeInputCheckOptions(YAML::Node* root, const std::string& source) {
  InputCheckOptions o;
  if (!root->IsMap() || !(*root)["input"]) return o;
  const YAML::Node section = (*root)["input"];
  if (!section.IsMap()) {
    throw std::runtime_error(YamlWhere(source, section.Mark()) + ": 'input' must be a mapping");
  }
  const std::map<std::string, double*> keys = {{"max_gyro", &o.max_gyro},
                                               {"max_accel", &o.max_accel},
                                               {"gravity_tolerance", &o.gravity_tolerance},
                                               {"constant_imu_duration", &o.constant_imu_duration},
                                               {"moving_translation", &o.moving_translation},
                                               {"moving_rotation", &o.moving_rotation},
                                               {"scan_time_tolerance", &o.scan_time_tolerance},
                                               {"max_imu_gap_error", &o.max_imu_gap_error}};
  for (const auto& kv : section) {
    const std::string key = kv.first.as<std::string>("");
    const auto it = keys.find(key);
    if (it == keys.end()) {
      throw std::runtime_error(YamlWhere(source, kv.first.Mark()) + ": unknown key 'input." + key +
                               "'");
    }
    try {
      *it->second = kv.second.as<double>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(YamlWhere(source, kv.second.Mark()) + ": input." + key +
                               " is not a number");
    }
  }
  try {
    o.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(YamlWhere(source, section.Mark()) + ": " + e.what());
  }
  root->remove("input");
  return o;
}

void ValidateIterationLimits(const OdometryConfig& config) {
  if (config.frontend.max_iterations > 100) {
    throw std::invalid_argument("lidar_frontend.max_iterations " +
                                std::to_string(config.frontend.max_iterations) +
                                " exceeds 100 association rounds per scan");
  }
  if (config.frontend.solver_iterations > 1000) {
    throw std::invalid_argument("lidar_frontend.solver_iterations " +
                                std::to_string(config.frontend.solver_iterations) +
                                " exceeds 1000 solver iterations per round");
  }
}

std::optional<std::string> CheckImuRange(const ImuSample& s, const InputCheckOptions& o) {
  const double w = s.gyro.norm(), f = s.accel.norm();
  std::ostringstream m;
  if (!std::isfinite(w) || w > o.max_gyro) {
    m << "|gyro| " << w << " rad/s beyond the physical range " << o.max_gyro
      << " rad/s (input.max_gyro)";
    return m.str();
  }
  if (!std::isfinite(f) || f > o.max_accel) {
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
    << " %): accelerometer units or axes cannot be right";
  return m.str();
}

size_t DropPointsBefore(int64_t previous_end_ns, int64_t tolerance_ns, LidarScan* scan) {
  size_t kept = 0;
  const size_t n = scan->points.size();
  for (size_t i = 0; i < n; ++i) {
    if (scan->times_ns[i] < previous_end_ns - tolerance_ns) continue;
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
