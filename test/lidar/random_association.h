// A random plane association for the point-to-plane factor tests: a point and a plane point
// within ±20 m, a random unit normal, a weight in [0.1, 1] (factors that take the point in
// another frame, e.g. the lidar frame with the extrinsic, ignore point_robot).
#pragma once

#include <cmath>
#include <random>

#include "ctlio/factors/lidar/point_to_plane.h"

namespace ctlio::testing {

inline PlaneAssociation RandomAssociation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PlaneAssociation m;
  m.point_robot = 20.0 * Vec3(u(rng), u(rng), u(rng));
  m.plane_point = 20.0 * Vec3(u(rng), u(rng), u(rng));
  m.plane_normal = Vec3(u(rng), u(rng), u(rng)).normalized();
  m.weight = 0.1 + 0.9 * std::abs(u(rng));
  return m;
}

}  // namespace ctlio::testing
