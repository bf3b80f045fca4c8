// Fixed-size Eigen aliases shared by every part of ctlio.
#pragma once

#include <Eigen/Core>

namespace ctlio {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

}  // namespace ctlio
