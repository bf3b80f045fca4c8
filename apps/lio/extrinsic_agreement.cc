#include "lio/extrinsic_agreement.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

namespace ctlio::lioapp {

std::string DescribeExtrinsic(const SE3& T) {
  const Eigen::AngleAxisd r(T.rotation());
  std::ostringstream s;
  s.precision(4);
  auto vec = [&](const Vec3& v) { s << '[' << v.x() << ' ' << v.y() << ' ' << v.z() << ']'; };
  s << "translation ";
  vec(T.translation());
  s << " m, rotation " << r.angle() * 180.0 / M_PI << " deg about ";
  vec(r.axis());
  return s.str();
}

std::string ExtrinsicDisagreement(const SE3& used, const std::string& used_name, const SE3& data,
                                  const std::string& data_name,
                                  const ExtrinsicTolerance& tolerance) {
  // The relative rotation's angle and the translations' distance: what a point at the lidar
  // would be moved by between the two (the lever arm matters only through the translation).
  const double deg =
      Eigen::AngleAxisd(used.rotation().transpose() * data.rotation()).angle() * 180.0 / M_PI;
  const double m = (used.translation() - data.translation()).norm();
  // Written so that NaN disagrees.
  if (deg <= tolerance.max_rotation_deg && m <= tolerance.max_translation_m) return "";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << used_name << " vs " << data_name << ": " << deg << " deg, " << 100.0 * m << " cm ("
    << used_name << ": " << DescribeExtrinsic(used) << "; " << data_name << ": "
    << DescribeExtrinsic(data) << ")";
  return s.str();
}

}  // namespace ctlio::lioapp
