#include "ctlio/io/extrinsic_check.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ctlio::io {

SE3 CheckedExtrinsic(double qw, double qx, double qy, double qz, const Vec3& t,
                     const std::string& where) {
  const Eigen::Vector4d q(qw, qx, qy, qz);
  auto fail = [&](const std::string& what) {
    std::ostringstream s;
    s.precision(17);
    s << where << "extrinsic " << what << " (quaternion w x y z = " << qw << " " << qx << " " << qy
      << " " << qz << ", translation = " << t.x() << " " << t.y() << " " << t.z() << ")";
    throw std::runtime_error(s.str());
  };
  if (!q.allFinite()) {
    fail("quaternion is not finite");
  }
  if (!t.allFinite()) {
    fail("translation is not finite");
  }
  const double n2 = q.squaredNorm();
  if (!(std::abs(n2 - 1.0) <= kQuaternionNormSqTolerance)) {
    std::ostringstream s;
    s << "quaternion is not a rotation: |q|^2 = " << n2 << ", outside 1 ± "
      << kQuaternionNormSqTolerance << " (tf2's tolerance)";
    fail(s.str());
  }
  return SE3(Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix(), t);
}

}  // namespace ctlio::io
