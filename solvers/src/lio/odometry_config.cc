#include "ctlio/solvers/lio/odometry_config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>

#include "ctlio/solvers/lio/config_composition.h"
#include "ctlio/solvers/lio/yaml_io.h"

namespace ctlio::lio {

namespace {

using Setter = YamlSetter;

Setter SetVec6(Vec6* field) {
  return [field](const YAML::Node& v) {
    if (!v.IsSequence() || v.size() != 6) throw YAML::Exception(v.Mark(), "need 6 numbers");
    for (int i = 0; i < 6; ++i) (*field)[i] = v[i].as<double>();
  };
}

// `set`, then every number of the (scalar or sequence) value must be finite: an extrinsic with a
// NaN passes the rotation check below (NaN compares false) and gives a NaN trajectory, an Inf one
// an Inf translation. The error names the file and the line of the offending number.
Setter FiniteExtrinsic(const std::string& source, const std::string& key, Setter set) {
  return [source, key, set](const YAML::Node& v) {
    set(v);  // the shape first: a wrong size stays "bad value"
    const size_t n = v.IsSequence() ? v.size() : 1;
    for (size_t i = 0; i < n; ++i) {
      const YAML::Node e = v.IsSequence() ? v[i] : v;
      if (!std::isfinite(e.as<double>())) {
        throw std::runtime_error(YamlWhere(source, e.Mark()) + ": " + key + "[" +
                                 std::to_string(i) + "] is " + e.Scalar() +
                                 ": an extrinsic must be finite");
      }
    }
  };
}

// A threshold: finite and > 0, else an error naming the file, the line and the key.
Setter SetPositive(double* field, const std::string& source, const std::string& key) {
  return [=](const YAML::Node& v) {
    const double x = v.as<double>();
    if (!(std::isfinite(x) && x > 0)) {
      throw std::runtime_error(YamlWhere(source, v.Mark()) + ": " + key + " = " + v.Scalar() +
                               " must be finite and > 0");
    }
    *field = x;
  };
}

// Applies `fields` to the mapping `node` (section `section` of `source`).
void ReadSection(const YAML::Node& node, const std::string& section, const std::string& source,
                 const std::map<std::string, Setter>& fields) {
  if (!node.IsDefined() || node.IsNull()) return;
  if (!node.IsMap()) {
    throw std::runtime_error(YamlWhere(source, node.Mark()) + ": '" + section +
                             "' must be a YAML mapping");
  }
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    const auto it = fields.find(key);
    if (it == fields.end()) {
      throw std::runtime_error(YamlWhere(source, kv.first.Mark()) + ": unknown key '" + section +
                               "." + key + "'");
    }
    try {
      it->second(kv.second);
    } catch (const YAML::Exception&) {
      throw std::runtime_error(YamlWhere(source, kv.second.Mark()) + ": bad value for '" + section +
                               "." + key + "'");
    }
  }
}

}  // namespace

LioMethod ParseLioMethod(const std::string& name) {
  if (name == "singer_lio") return LioMethod::kSingerLio;
  if (name == "lidar_gyro") return LioMethod::kLidarGyro;
  if (name == "lidar_only") return LioMethod::kLidarOnly;
  if (name == "imu_input") return LioMethod::kImuInput;
  throw std::invalid_argument("unknown method '" + name +
                              "' (singer_lio, lidar_gyro, lidar_only, imu_input)");
}

std::string LioMethodName(LioMethod method) {
  switch (method) {
    case LioMethod::kSingerLio:
      return "singer_lio";
    case LioMethod::kLidarGyro:
      return "lidar_gyro";
    case LioMethod::kLidarOnly:
      return "lidar_only";
    case LioMethod::kImuInput:
      return "imu_input";
  }
  return "?";
}

const char* ScanStatusName(ScanStatus status) {
  switch (status) {
    case ScanStatus::kOk:
      return "ok";
    case ScanStatus::kInitialising:
      return "initialising";
    case ScanStatus::kDegenerate:
      return "degenerate";
    case ScanStatus::kImuGap:
      return "imu_gap";
    case ScanStatus::kFailed:
      return "failed";
    case ScanStatus::kSuspect:
      return "suspect";
  }
  return "?";
}

namespace {

// The parts of the top level that are combined after reading (method name, extrinsic pieces,
// the per-method overrides).
struct TopLevel {
  std::string method;
  bool have_extrinsic = false;
  Vec6 extrinsic_xyz_rpy = Vec6::Zero();
  std::vector<double> extrinsic_rotation;  // optional 3×3 row-major
  // `translation`, which wins over xyz_rpy's first three whatever the key order: in a composed
  // config (a calibration.yaml over a config with xyz_rpy) the later file's key comes last or
  // in the earlier file's place.
  std::vector<double> extrinsic_translation;
  YAML::Node per_method;
  YAML::Node imus;
};

// Applies the sections of the mapping `root` onto *c: keys absent keep *c's values. `top` is
// null inside a per-method override, where only the method-dependent sections (gp, imu, init,
// window, lidar_frontend, degeneracy) are allowed; `where` prefixes key names in messages.
void ApplySections(const YAML::Node& root, const std::string& source, const std::string& where,
                   OdometryConfig* c, TopLevel* top) {
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    const std::string section = where + key;
    if (top == nullptr && (key == "method" || key == "extrinsic" || key == "input" ||
                           key == "per_method" || key == "imus" || key == "calibration")) {
      throw std::runtime_error(YamlWhere(source, kv.first.Mark()) + ": '" + section +
                               "' cannot be set per method");
    }
    if (key == "method") {
      top->method = v.as<std::string>();
    } else if (key == "per_method") {
      if (!v.IsMap()) {
        throw std::runtime_error(YamlWhere(source, v.Mark()) +
                                 ": 'per_method' must be a mapping of method names");
      }
      top->per_method = v;
    } else if (key == "imus") {
      if (!v.IsSequence()) {
        throw std::runtime_error(YamlWhere(source, v.Mark()) +
                                 ": 'imus' must be a list of IMU mappings");
      }
      top->imus = v;
    } else if (key == "gp") {
      ReadSection(v, section, source, {{"qc", SetVec6(&c->qc)}, {"alpha", SetVec6(&c->alpha)}});
    } else if (key == "imu") {
      ReadSection(v, section, source,
                  {{"accel_variance", SetFromYaml(&c->accel_variance)},
                   {"accel_loss_scale", SetFromYaml(&c->accel_loss_scale)},
                   {"accel_loss_relax_bias_sigma", SetFromYaml(&c->accel_loss_relax_bias_sigma)},
                   {"accel_loss_relaxed_scale", SetFromYaml(&c->accel_loss_relaxed_scale)},
                   {"gyro_variance", SetFromYaml(&c->gyro_variance)},
                   {"bias_accel_walk", SetFromYaml(&c->bias_accel_walk)},
                   {"bias_gyro_walk", SetFromYaml(&c->bias_gyro_walk)},
                   {"bias_walk_period", SetFromYaml(&c->bias_walk_period)},
                   {"initial_bias_accel_variance", SetFromYaml(&c->initial_bias_accel_variance)},
                   {"initial_bias_gyro_variance", SetFromYaml(&c->initial_bias_gyro_variance)},
                   {"gravity", SetFromYaml(&c->gravity)},
                   {"exact_specific_force", SetFromYaml(&c->exact_specific_force)},
                   {"input_accel_sigma", SetFromYaml(&c->input_accel_sigma)},
                   {"input_gyro_sigma", SetFromYaml(&c->input_gyro_sigma)},
                   {"input_midpoint", SetFromYaml(&c->input_midpoint)},
                   {"input_interpolation", SetFromYaml(&c->input_interpolation)},
                   {"input_substeps", SetInRange(&c->input_substeps, 1, kMaxInputSubsteps, source,
                                                 section + ".input_substeps")},
                   {"rate_hint", SetFromYaml(&c->imu_rate_hint)},
                   {"gap_velocity_walk", SetFromYaml(&c->gap_velocity_walk)},
                   {"gap_hold_max", SetFromYaml(&c->gap_hold_max)},
                   {"gap_zero_order_hold", SetFromYaml(&c->gap_zero_order_hold)},
                   {"residual_blocks", SetFromYaml(&c->imu_residual_blocks)},
                   {"input_imu", SetFromYaml(&c->input_imu)}});
    } else if (key == "init") {
      ReadSection(v, section, source,
                  {{"gravity_duration", SetFromYaml(&c->gravity_init_duration)},
                   {"gravity_max_std", SetFromYaml(&c->gravity_init_max_std)},
                   {"min_associations", SetFromYaml(&c->min_associations)},
                   {"max_imu_gap", SetFromYaml(&c->max_imu_gap)},
                   {"max_scan_translation", SetFromYaml(&c->max_scan_translation)}});
    } else if (key == "window") {
      ReadSection(
          v, section, source,
          {{"knots", SetInRange(&c->window_knots, 2, kMaxWindowKnots, source, section + ".knots")},
           {"knots_per_scan", SetFromYaml(&c->knots_per_scan)},
           {"adaptive_knots_max", SetFromYaml(&c->adaptive_knots.max_knots_per_scan)},
           {"adaptive_knots_gyro_curvature", SetFromYaml(&c->adaptive_knots.gyro_curvature)},
           {"adaptive_knots_accel_curvature", SetFromYaml(&c->adaptive_knots.accel_curvature)},
           {"adaptive_knots_accel_variance", SetFromYaml(&c->adaptive_knots.accel_variance_floor)},
           {"adaptive_knots_gyro_variance", SetFromYaml(&c->adaptive_knots.gyro_variance_floor)},
           {"adaptive_knots_max_keypoints",
            SetInRange(&c->adaptive_knots.max_keypoints, 0, 1000000, source,
                       section + ".adaptive_knots_max_keypoints")},
           {"slow_sweep_max_keypoints",
            SetInRange(&c->slow_sweep_keypoints.max_keypoints, 0, 1000000, source,
                       section + ".slow_sweep_max_keypoints")},
           {"slow_sweep_speed", SetFromYaml(&c->slow_sweep_keypoints.speed)},
           {"threads",
            SetInRange(&c->solver_threads, 1, kMaxConfigThreads, source, section + ".threads")},
           {"overlap", SetFromYaml(&c->overlap_stages)},
           {"estimate_gravity", SetFromYaml(&c->estimate_gravity)},
           {"imu_prediction", SetFromYaml(&c->imu_prediction)},
           {"gap_prediction_span", SetFromYaml(&c->gap_prediction_span)},
           {"pose_covariance", SetFromYaml(&c->pose_covariance)},
           {"pose_covariance_lidar_scale", SetFromYaml(&c->pose_covariance_lidar_scale)},
           {"pose_covariance_adaptive", SetFromYaml(&c->pose_covariance_adaptive)},
           {"pose_covariance_lidar_neff", SetFromYaml(&c->pose_covariance_lidar_neff)},
           {"pose_covariance_lidar_floor_m", SetFromYaml(&c->pose_covariance_lidar_floor_m)},
           {"pose_covariance_lidar_floor_rad", SetFromYaml(&c->pose_covariance_lidar_floor_rad)},
           {"pose_covariance_map_sigma_m", SetFromYaml(&c->pose_covariance_map_sigma_m)},
           {"pose_covariance_map_sigma_rad", SetFromYaml(&c->pose_covariance_map_sigma_rad)},
           {"pose_covariance_map_growth", SetFromYaml(&c->pose_covariance_map_growth)},
           {"pose_covariance_misfit", SetFromYaml(&c->pose_covariance_misfit)}});
    } else if (key == "extrinsic") {
      top->have_extrinsic = true;
      ReadSection(v, key, source,
                  {{"xyz_rpy",
                    FiniteExtrinsic(source, "extrinsic.xyz_rpy", SetVec6(&top->extrinsic_xyz_rpy))},
                   {"rotation", FiniteExtrinsic(source, "extrinsic.rotation",
                                                SetFromYaml(&top->extrinsic_rotation))},
                   {"translation",
                    FiniteExtrinsic(source, "extrinsic.translation", [top](const YAML::Node& n) {
                      const auto t = n.as<std::vector<double>>();
                      if (t.size() != 3) throw YAML::Exception(n.Mark(), "need 3 numbers");
                      top->extrinsic_translation = t;
                    })}});
    } else if (key == "degeneracy") {
      ReadSection(v, section, source,
                  {{"enabled", SetFromYaml(&c->degeneracy.enabled)},
                   {"translation_threshold", SetFromYaml(&c->degeneracy.translation_threshold)},
                   {"rotation_threshold", SetFromYaml(&c->degeneracy.rotation_threshold)},
                   {"remap_information", SetFromYaml(&c->degeneracy.remap_information)},
                   {"remap", SetFromYaml(&c->degeneracy.remap)}});
    } else if (key == "calibration") {
      CalibrationOptions& o = c->calibration;
      ReadSection(
          v, section, source,
          {{"estimate_time_offset", SetFromYaml(&o.estimate_time_offset)},
           {"time_offset_s", SetFromYaml(&o.time_offset_s)},
           {"time_offset_prior_sigma_s", SetFromYaml(&o.time_offset_prior_sigma_s)},
           {"estimate_extrinsic", SetFromYaml(&o.estimate_extrinsic)},
           {"extrinsic_prior_sigma_deg", SetFromYaml(&o.extrinsic_prior_sigma_deg)},
           {"extrinsic_prior_sigma_m", SetFromYaml(&o.extrinsic_prior_sigma_m)},
           {"observability_horizon_scans", SetFromYaml(&o.observability_horizon_scans)},
           {"time_offset_observability_threshold",
            SetFromYaml(&o.time_offset_observability_threshold)},
           {"rotation_observability_threshold", SetFromYaml(&o.rotation_observability_threshold)},
           {"translation_observability_threshold",
            SetFromYaml(&o.translation_observability_threshold)},
           {"hold_unobservable", SetFromYaml(&o.hold_unobservable)},
           {"hold_information", SetFromYaml(&o.hold_information)},
           {"warmup_replay_s", SetFromYaml(&o.warmup_replay_s)},
           {"warmup_replay_passes", SetFromYaml(&o.warmup_replay_passes)},
           {"warmup_replay_hold", SetFromYaml(&o.warmup_replay_hold)},
           {"warmup_replay_freeze", SetFromYaml(&o.warmup_replay_freeze)},
           {"warmup_forget_s", SetFromYaml(&o.warmup_forget_s)},
           {"warmup_forget_restart_map", SetFromYaml(&o.warmup_forget_restart_map)},
           {"write_max_sigma_s",
            SetPositive(&o.write_max_sigma_s, source, section + ".write_max_sigma_s")},
           {"write_max_sigma_deg",
            SetPositive(&o.write_max_sigma_deg, source, section + ".write_max_sigma_deg")},
           {"write_max_sigma_m",
            SetPositive(&o.write_max_sigma_m, source, section + ".write_max_sigma_m")},
           {"write_max_sigma_ratio", SetFromYaml(&o.write_max_sigma_ratio)},
           {"write_max_unobservable_fraction", SetFromYaml(&o.write_max_unobservable_fraction)},
           {"write_max_drift_sigmas", SetFromYaml(&o.write_max_drift_sigmas)}});
    } else if (key == "lidar_frontend") {
      c->frontend = LidarFrontendOptionsFromYaml(v, source, c->frontend);
    } else if (key == "input") {
      InputCheckOptions& o = c->input;
      ReadSection(v, section, source,
                  {{"max_gyro", SetFromYaml(&o.max_gyro)},
                   {"max_accel", SetFromYaml(&o.max_accel)},
                   {"gravity_tolerance", SetFromYaml(&o.gravity_tolerance)},
                   {"constant_imu_duration", SetFromYaml(&o.constant_imu_duration)},
                   {"moving_translation", SetFromYaml(&o.moving_translation)},
                   {"moving_rotation", SetFromYaml(&o.moving_rotation)},
                   {"scan_time_tolerance", SetFromYaml(&o.scan_time_tolerance)},
                   {"max_imu_gap_error", SetFromYaml(&o.max_imu_gap_error)},
                   {"accel_scale", SetFromYaml(&o.accel_scale)},
                   {"strict", SetFromYaml(&o.strict)}});
    } else {
      throw std::runtime_error(YamlWhere(source, kv.first.Mark()) + ": unknown key '" + section +
                               "'");
    }
  }
}

void ValidateNaming(const OdometryConfig& c, const std::string& source, const std::string& what) {
  try {
    c.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + what + ": " + e.what());
  }
}

}  // namespace

double OdometryConfig::AccelVariance(int j) const {
  return imus.empty() || imus[j].accel_variance <= 0 ? accel_variance : imus[j].accel_variance;
}

double OdometryConfig::GyroVariance(int j) const {
  return imus.empty() || imus[j].gyro_variance <= 0 ? gyro_variance : imus[j].gyro_variance;
}

OdometryConfig OdometryConfig::ForMethod(LioMethod m) const {
  const auto it = per_method.find(m);
  OdometryConfig c = it == per_method.end() ? *this : *it->second;
  c.method = m;
  c.per_method.clear();
  return c;
}

OdometryConfig OdometryConfigFromYaml(const YAML::Node& root, const std::string& source) {
  OdometryConfig c;
  if (!root.IsDefined() || root.IsNull()) return c;
  if (!root.IsMap()) throw std::runtime_error(source + ": the config must be a YAML mapping");
  TopLevel top;
  top.method = LioMethodName(c.method);
  ApplySections(root, source, "", &c, &top);
  try {
    c.method = ParseLioMethod(top.method);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }
  if (top.have_extrinsic) {
    Mat3 C;
    if (!top.extrinsic_rotation.empty()) {
      if (top.extrinsic_rotation.size() != 9)
        throw std::runtime_error(source + ": extrinsic.rotation needs 9 numbers (row-major)");
      C = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
          top.extrinsic_rotation.data());
      if ((C * C.transpose() - Mat3::Identity()).norm() > 1e-6 || C.determinant() < 0)
        throw std::runtime_error(source + ": extrinsic.rotation is not a rotation matrix");
    } else {
      const Vec3 rpy = top.extrinsic_xyz_rpy.tail<3>();
      C = (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
           Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
              .toRotationMatrix();
    }
    const Vec3 p = top.extrinsic_translation.empty()
                       ? Vec3(top.extrinsic_xyz_rpy.head<3>())
                       : Vec3(top.extrinsic_translation[0], top.extrinsic_translation[1],
                              top.extrinsic_translation[2]);
    c.T_imu_lidar = SE3(C, p);
  }
  if (top.imus) {
    for (size_t j = 0; j < top.imus.size(); ++j) {
      const std::string section = "imus[" + std::to_string(j) + "]";
      Vec6 xyz_rpy = Vec6::Zero();
      OdometryConfig::ImuSensor sensor;
      ReadSection(top.imus[j], section, source,
                  {{"xyz_rpy", FiniteExtrinsic(source, section + ".xyz_rpy", SetVec6(&xyz_rpy))},
                   {"translation", FiniteExtrinsic(source, section + ".translation",
                                                   [&xyz_rpy](const YAML::Node& n) {
                                                     const auto t = n.as<std::vector<double>>();
                                                     if (t.size() != 3)
                                                       throw YAML::Exception(n.Mark(),
                                                                             "need 3 numbers");
                                                     xyz_rpy.head<3>() = Vec3(t[0], t[1], t[2]);
                                                   })},
                   {"accel_variance", SetFromYaml(&sensor.accel_variance)},
                   {"gyro_variance", SetFromYaml(&sensor.gyro_variance)}});
      const Vec3 rpy = xyz_rpy.tail<3>();
      const Mat3 C =
          (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
           Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
              .toRotationMatrix();
      sensor.T_robot_imu = SE3(C, xyz_rpy.head<3>());
      c.imus.push_back(sensor);
    }
  }
  ValidateNaming(c, source, "");
  // Per-method overrides: each applied onto the complete base (whatever the key order).
  if (top.per_method) {
    for (const auto& kv : top.per_method) {
      const std::string name = kv.first.as<std::string>();
      LioMethod m;
      try {
        m = ParseLioMethod(name);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(YamlWhere(source, kv.first.Mark()) + ": per_method: " + e.what());
      }
      if (!kv.second.IsMap()) {
        throw std::runtime_error(YamlWhere(source, kv.second.Mark()) + ": 'per_method." + name +
                                 "' must be a YAML mapping");
      }
      auto override_config = std::make_shared<OdometryConfig>(c);
      ApplySections(kv.second, source, "per_method." + name + ".", override_config.get(), nullptr);
      override_config->method = m;
      ValidateNaming(*override_config, source, " (per_method." + name + ")");
      c.per_method[m] = override_config;
    }
  }
  return c;
}

YAML::Node LoadOdometryYaml(const std::string& path) {
  return ComposeOdometryYaml(SplitConfigList(path));
}

OdometryConfig LoadOdometryConfig(const std::string& path) {
  const std::vector<std::string> files = SplitConfigList(path);
  return OdometryConfigFromYaml(ComposeOdometryYaml(files), files.back());
}

}  // namespace ctlio::lio
