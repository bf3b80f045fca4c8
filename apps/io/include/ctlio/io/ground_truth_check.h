// One rule for a ground-truth pose, whichever reader it comes from (a bag's nav_msgs/Odometry, the
// ctlio layout's ground_truth.csv, Newer College's registered_poses.csv, a TUM file): every
// component finite and the quaternion of unit norm within kGroundTruthQuaternionTolerance, else an
// error naming where the pose came from. The folder readers' text fields already refuse "nan";
// a bag's binary doubles did not, and one NaN pose made the ATE "nan" and a good run a failure.
// Header-only, so that every reader (apps/io and apps/io/rosbag) uses it without a new source.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::io {

// |‖q‖ − 1| accepted for a ground-truth quaternion (the folder readers' long-standing rule: a
// pose written with 4+ decimals passes; a zero or a scaled quaternion does not).
inline constexpr double kGroundTruthQuaternionTolerance = 1e-3;

// The pose (q normalised, t). Throws std::runtime_error "<where>ground-truth pose …" when a
// component is not finite or |‖q‖ − 1| > kGroundTruthQuaternionTolerance; `where` ends in ": ".
inline SE3 CheckedGroundTruthPose(double qw, double qx, double qy, double qz, const Vec3& t,
                                  const std::string& where) {
  const bool finite = std::isfinite(qw) && std::isfinite(qx) && std::isfinite(qy) &&
                      std::isfinite(qz) && t.allFinite();
  if (!finite) {
    throw std::runtime_error(where + "ground-truth pose is not finite (q = [" + std::to_string(qw) +
                             ", " + std::to_string(qx) + ", " + std::to_string(qy) + ", " +
                             std::to_string(qz) + "], t = [" + std::to_string(t.x()) + ", " +
                             std::to_string(t.y()) + ", " + std::to_string(t.z()) + "])");
  }
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!(std::abs(q.norm() - 1.0) <= kGroundTruthQuaternionTolerance)) {
    throw std::runtime_error(where + "ground-truth quaternion norm " + std::to_string(q.norm()) +
                             " is not 1");
  }
  return SE3(q.normalized(), t);
}

}  // namespace ctlio::io
