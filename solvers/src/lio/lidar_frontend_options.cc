#include "ctlio/solvers/lio/lidar_frontend_options.h"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>
#include <stdexcept>

#include "ctlio/solvers/lio/yaml_io.h"

namespace ctlio::lio {

namespace {}  // namespace

void LidarFrontendOptions::Validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("LidarFrontendOptions: ") + what);
  };
  require(min_range >= 0.0 && max_range > min_range, "need 0 <= min_range < max_range");
  require(voxel_size > 0.0 && initial_voxel_size > 0.0, "voxel sizes must be positive");
  require(initial_scans >= 0, "initial_scans must be >= 0");
  require(keypoint_voxel_size > 0.0, "keypoint_voxel_size must be positive");
  require(max_keypoints >= 0, "max_keypoints must be >= 0 (0 = no cap)");
  require(map_voxel_size > 0.0, "map_voxel_size must be positive");
  // A voxel wider than the lidar's range keeps a handful of points per sweep: the lidar then
  // fixes no pose and the run is IMU dead reckoning with exit 0 (voxel_size 1e30 gave 5x the
  // clean ATE, every second scan degenerate, no error).
  require(voxel_size <= max_range && initial_voxel_size <= max_range &&
              keypoint_voxel_size <= max_range && map_voxel_size <= max_range,
          "voxel sizes (voxel_size, initial_voxel_size, keypoint_voxel_size, map_voxel_size) "
          "must not exceed max_range");
  require(max_points_per_voxel >= 1 && max_points_per_voxel <= kMaxPointsPerVoxel,
          "max_points_per_voxel must be in [1, 10000]");
  require(min_point_distance >= 0.0, "min_point_distance must be >= 0");
  require(max_map_distance > 0.0, "max_map_distance must be positive");
  require(min_neighbours >= 3, "min_neighbours must be >= 3 (a plane needs three points)");
  require(max_neighbours >= min_neighbours && max_neighbours <= kMaxNeighbours,
          "max_neighbours must be in [min_neighbours, 1000]");
  require(max_plane_distance > 0.0, "max_plane_distance must be positive");
  require(association == "knn" || association == "voxel_plane",
          "association must be knn or voxel_plane");
  require(voxel_plane_max_thickness >= 0.0, "voxel_plane_max_thickness must be >= 0");
  require(max_plane_thickness >= 0.0, "max_plane_thickness must be >= 0 (0 = off)");
  require(plane_thickness_noise >= 0.0 && plane_thickness_noise <= 100.0,
          "plane_thickness_noise must be in [0, 100] (0 = off)");
  require(line_neighbourhood_ratio >= 0.0 && line_neighbourhood_ratio <= 0.99,
          "line_neighbourhood_ratio must be in [0, 0.99] (0 = off)");
  require(threads >= 1 && threads <= kMaxConfigThreads, "threads must be in [1, 256]");
  require(max_iterations >= 1 && solver_iterations >= 1, "iteration counts must be >= 1");
  // Upper bounds: with zero convergence thresholds the solver runs to these on every scan, so an
  // unbounded value is a run that never ends.
  require(max_iterations <= 100, "max_iterations must be <= 100 association rounds per scan");
  require(solver_iterations <= 1000, "solver_iterations must be <= 1000 per round");
  require(max_iterations_without_imu >= 0 && max_iterations_without_imu <= 100,
          "max_iterations_without_imu must be in [0, 100] (0 = max_iterations)");
  require(solver_iterations_without_imu >= 0 && solver_iterations_without_imu <= 1000,
          "solver_iterations_without_imu must be in [0, 1000] (0 = solver_iterations)");
  require(max_correction_without_imu >= 0.0 && max_correction_without_imu <= 1000.0,
          "max_correction_without_imu must be in [0, 1000] m (0 = off)");
  require(max_rotation_correction_without_imu >= 0.0 && max_rotation_correction_without_imu <= M_PI,
          "max_rotation_correction_without_imu must be in [0, pi] rad (0 = off)");
  require(high_speed >= 0.0 && high_speed <= 1000.0,
          "high_speed must be in [0, 1000] m/s (0 = off)");
  require(max_iterations_high_speed >= 0 && max_iterations_high_speed <= 100,
          "max_iterations_high_speed must be in [0, 100] (0 = max_iterations)");
  require(solver_iterations_high_speed >= 0 && solver_iterations_high_speed <= 1000,
          "solver_iterations_high_speed must be in [0, 1000] (0 = solver_iterations)");
  require(loss == "cauchy" || loss == "huber" || loss == "none",
          "loss must be cauchy, huber or none");
  require(residual_blocks == "point" || residual_blocks == "interval" ||
              residual_blocks == "square_root",
          "residual_blocks must be point, interval or square_root");
  require(point_noise_sigma > 0.0, "point_noise_sigma must be positive");
  require(point_noise_angle >= 0.0 && point_noise_angle <= 0.1,
          "point_noise_angle must be in [0, 0.1] rad (0 = off)");
  require(loss_scale > 0.0, "loss_scale must be positive");
  require(convergence_translation >= 0.0 && convergence_rotation >= 0.0,
          "convergence thresholds must be >= 0");
  require(reassociation_distance >= 0.0, "reassociation_distance must be >= 0 (0 = always search)");
}

LidarFrontendOptions LidarFrontendOptionsFromYaml(const YAML::Node& node, const std::string& source,
                                                  const LidarFrontendOptions& base) {
  LidarFrontendOptions o = base;
  if (!node.IsDefined() || node.IsNull()) return o;
  if (!node.IsMap()) {
    throw std::runtime_error(YamlWhere(source, node.Mark()) +
                             ": lidar front-end options must be a YAML mapping");
  }
  const std::map<std::string, std::function<void(const YAML::Node&)>> fields = {
      {"min_range", SetFromYaml(&o.min_range)},
      {"max_range", SetFromYaml(&o.max_range)},
      {"voxel_size", SetFromYaml(&o.voxel_size)},
      {"initial_voxel_size", SetFromYaml(&o.initial_voxel_size)},
      {"initial_scans", SetFromYaml(&o.initial_scans)},
      {"keypoint_voxel_size", SetFromYaml(&o.keypoint_voxel_size)},
      {"max_keypoints", SetFromYaml(&o.max_keypoints)},
      {"map_voxel_size", SetFromYaml(&o.map_voxel_size)},
      {"max_points_per_voxel", SetInRange(&o.max_points_per_voxel, 1, kMaxPointsPerVoxel, source,
                                          "lidar_frontend.max_points_per_voxel")},
      {"min_point_distance", SetFromYaml(&o.min_point_distance)},
      {"max_map_distance", SetFromYaml(&o.max_map_distance)},
      {"max_neighbours",
       SetInRange(&o.max_neighbours, 3, kMaxNeighbours, source, "lidar_frontend.max_neighbours")},
      {"min_neighbours", SetFromYaml(&o.min_neighbours)},
      {"max_plane_distance", SetFromYaml(&o.max_plane_distance)},
      {"association", SetFromYaml(&o.association)},
      {"voxel_plane_max_thickness", SetFromYaml(&o.voxel_plane_max_thickness)},
      {"max_plane_thickness", SetFromYaml(&o.max_plane_thickness)},
      {"plane_thickness_noise", SetInRange(&o.plane_thickness_noise, 0.0, 100.0, source,
                                           "lidar_frontend.plane_thickness_noise")},
      {"line_neighbourhood_ratio", SetInRange(&o.line_neighbourhood_ratio, 0.0, 0.99, source,
                                              "lidar_frontend.line_neighbourhood_ratio")},
      {"threads", SetInRange(&o.threads, 1, kMaxConfigThreads, source, "lidar_frontend.threads")},
      {"max_iterations", SetFromYaml(&o.max_iterations)},
      {"solver_iterations", SetFromYaml(&o.solver_iterations)},
      {"max_iterations_without_imu", SetFromYaml(&o.max_iterations_without_imu)},
      {"solver_iterations_without_imu", SetFromYaml(&o.solver_iterations_without_imu)},
      {"max_correction_without_imu", SetFromYaml(&o.max_correction_without_imu)},
      {"max_rotation_correction_without_imu", SetFromYaml(&o.max_rotation_correction_without_imu)},
      {"high_speed", SetFromYaml(&o.high_speed)},
      {"max_iterations_high_speed", SetFromYaml(&o.max_iterations_high_speed)},
      {"solver_iterations_high_speed", SetFromYaml(&o.solver_iterations_high_speed)},
      {"point_noise_sigma", SetFromYaml(&o.point_noise_sigma)},
      {"point_noise_angle",
       SetInRange(&o.point_noise_angle, 0.0, 0.1, source, "lidar_frontend.point_noise_angle")},
      {"loss", SetFromYaml(&o.loss)},
      {"loss_scale", SetFromYaml(&o.loss_scale)},
      {"residual_blocks", SetFromYaml(&o.residual_blocks)},
      {"convergence_translation", SetFromYaml(&o.convergence_translation)},
      {"convergence_rotation", SetFromYaml(&o.convergence_rotation)},
      {"reassociation_distance", SetFromYaml(&o.reassociation_distance)},
  };
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    const auto it = fields.find(key);
    if (it == fields.end()) {
      throw std::runtime_error(YamlWhere(source, kv.first.Mark()) +
                               ": unknown lidar front-end key '" + key + "'");
    }
    try {
      it->second(kv.second);
    } catch (const YAML::Exception&) {
      throw std::runtime_error(YamlWhere(source, kv.second.Mark()) + ": bad value for '" + key +
                               "'");
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
  const YAML::Node root = LoadYamlFile(path, "lidar front-end options");
  // Accept either the options at the top level or under a "lidar_frontend" key, so that the
  // same block can live inside a larger pipeline config.
  const YAML::Node& const_root = root;
  const YAML::Node node =
      const_root.IsMap() && const_root["lidar_frontend"] ? const_root["lidar_frontend"] : root;
  return LidarFrontendOptionsFromYaml(node, path);
}

}  // namespace ctlio::lio
