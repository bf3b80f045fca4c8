#include "ctlio/solvers/lio/lidar_frontend_options.h"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ctlio::lio {

namespace {

std::string Where(const std::string& source, const YAML::Mark& mark) {
  std::ostringstream s;
  s << source;
  if (mark.line >= 0) s << ":" << mark.line + 1;
  return s.str();
}

template <typename T>
std::function<void(const YAML::Node&)> Setter(T* field) {
  return [field](const YAML::Node& value) { *field = value.as<T>(); };
}

}  // namespace

void LidarFrontendOptions::Validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("LidarFrontendOptions: ") + what);
  };
  require(min_range >= 0.0 && max_range > min_range, "need 0 <= min_range < max_range");
  require(voxel_size > 0.0 && initial_voxel_size > 0.0, "voxel sizes must be positive");
  require(initial_scans >= 0, "initial_scans must be >= 0");
  require(keypoint_voxel_size > 0.0, "keypoint_voxel_size must be positive");
  require(map_voxel_size > 0.0, "map_voxel_size must be positive");
  require(max_points_per_voxel >= 1, "max_points_per_voxel must be >= 1");
  require(min_point_distance >= 0.0, "min_point_distance must be >= 0");
  require(max_map_distance > 0.0, "max_map_distance must be positive");
  require(min_neighbours >= 3, "min_neighbours must be >= 3 (a plane needs three points)");
  require(max_neighbours >= min_neighbours, "max_neighbours must be >= min_neighbours");
  require(max_plane_distance > 0.0, "max_plane_distance must be positive");
  require(max_iterations >= 1 && solver_iterations >= 1, "iteration counts must be >= 1");
  require(loss == "cauchy" || loss == "huber" || loss == "none",
          "loss must be cauchy, huber or none");
  require(point_noise_sigma > 0.0, "point_noise_sigma must be positive");
  require(loss_scale > 0.0, "loss_scale must be positive");
  require(convergence_translation >= 0.0 && convergence_rotation >= 0.0,
          "convergence thresholds must be >= 0");
}

LidarFrontendOptions LidarFrontendOptionsFromYaml(const YAML::Node& node,
                                                  const std::string& source) {
  LidarFrontendOptions o;
  if (!node.IsDefined() || node.IsNull()) return o;
  if (!node.IsMap()) {
    throw std::runtime_error(Where(source, node.Mark()) +
                             ": lidar front-end options must be a YAML mapping");
  }
  const std::map<std::string, std::function<void(const YAML::Node&)>> fields = {
      {"min_range", Setter(&o.min_range)},
      {"max_range", Setter(&o.max_range)},
      {"voxel_size", Setter(&o.voxel_size)},
      {"initial_voxel_size", Setter(&o.initial_voxel_size)},
      {"initial_scans", Setter(&o.initial_scans)},
      {"keypoint_voxel_size", Setter(&o.keypoint_voxel_size)},
      {"map_voxel_size", Setter(&o.map_voxel_size)},
      {"max_points_per_voxel", Setter(&o.max_points_per_voxel)},
      {"min_point_distance", Setter(&o.min_point_distance)},
      {"max_map_distance", Setter(&o.max_map_distance)},
      {"max_neighbours", Setter(&o.max_neighbours)},
      {"min_neighbours", Setter(&o.min_neighbours)},
      {"max_plane_distance", Setter(&o.max_plane_distance)},
      {"max_iterations", Setter(&o.max_iterations)},
      {"solver_iterations", Setter(&o.solver_iterations)},
      {"point_noise_sigma", Setter(&o.point_noise_sigma)},
      {"loss", Setter(&o.loss)},
      {"loss_scale", Setter(&o.loss_scale)},
      {"convergence_translation", Setter(&o.convergence_translation)},
      {"convergence_rotation", Setter(&o.convergence_rotation)},
  };
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    const auto it = fields.find(key);
    if (it == fields.end()) {
      throw std::runtime_error(Where(source, kv.first.Mark()) + ": unknown lidar front-end key '" +
                               key + "'");
    }
    try {
      it->second(kv.second);
    } catch (const YAML::Exception&) {
      throw std::runtime_error(Where(source, kv.second.Mark()) + ": bad value for '" + key + "'");
    }
  }
  try {
    o.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }
  return o;
}

LidarFrontendOptions LoadLidarFrontendOptions(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(path + ": cannot open lidar front-end options");
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(Where(path, e.mark) + ": " + e.msg);
  }
  // Accept either the options at the top level or under a "lidar_frontend" key, so that the
  // same block can live inside a larger pipeline config.
  const YAML::Node& const_root = root;
  const YAML::Node node =
      const_root.IsMap() && const_root["lidar_frontend"] ? const_root["lidar_frontend"] : root;
  return LidarFrontendOptionsFromYaml(node, path);
}

}  // namespace ctlio::lio
