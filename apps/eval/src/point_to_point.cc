#include "ctlio/eval/point_to_point.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdint>
#include <unordered_set>

namespace ctlio::eval {

std::vector<Vec3> FirstPointPerVoxel(const std::vector<Vec3>& points, double voxel) {
  if (!(voxel > 0.0)) return points;
  std::unordered_set<uint64_t> seen;
  std::vector<Vec3> out;
  for (const Vec3& p : points) {
    const auto key = [&](int i) { return uint64_t(int64_t(std::floor(p[i] / voxel)) & 0x1FFFFF); };
    if (seen.insert(key(0) | key(1) << 21 | key(2) << 42).second) out.push_back(p);
  }
  return out;
}

void PointToPointSystem::Add(const Vec3& e, const Eigen::Matrix<double, 3, 6>& J, double kappa) {
  const double s = kappa + e.squaredNorm();
  const double w = kappa * kappa / (s * s);
  H_ += w * J.transpose() * J;
  g_ += w * J.transpose() * e;
  ++used_;
}

Vec6 PointToPointSystem::Step(double damping) const {
  Eigen::Matrix<double, 6, 6> H = H_;
  if (damping > 0.0) H.diagonal() *= 1.0 + damping;
  return -H.ldlt().solve(g_);
}

}  // namespace ctlio::eval
