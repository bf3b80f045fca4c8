// The check of an extrinsic (a rigid transform between two sensors) read from a dataset: a bag's
// /tf_static, a folder's files. Eigen and Sophus normalise whatever they are given without a word:
// a zero quaternion becomes identity, a NaN one a NaN rotation that the odometry turns into a NaN
// trajectory with exit 0. Readers build extrinsics through CheckedExtrinsic, which refuses both.
// (The odometry config's `extrinsic:` is checked where it is parsed, with its YAML line:
// solvers/src/lio/odometry_config.cc.)
#pragma once

#include <string>

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::io {

// Accepted |‖q‖² − 1|: tf2's own tolerance (tf2::BufferCore ignores a transform beyond it as an
// "invalid quaternion"), so a /tf_static that every ROS tool accepts is accepted here and one that
// tf2 would drop is refused. It admits quaternions printed with 3–4 decimals (‖q‖ within 0.5 % of
// 1); a zero quaternion (|‖q‖² − 1| = 1) is far outside it.
constexpr double kQuaternionNormSqTolerance = 1e-2;

// T = (normalised q, t). Throws std::runtime_error "<where>extrinsic <what>" when a component of
// q or t is not finite, or |‖q‖² − 1| > kQuaternionNormSqTolerance (the values are given).
SE3 CheckedExtrinsic(double qw, double qx, double qy, double qz, const Vec3& t,
                     const std::string& where);

}  // namespace ctlio::io
