#include "ctlio/eval/point_icp.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdint>
#include <unordered_set>

#include "ctlio/eval/geometry_statistics.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::eval {
namespace {

// One original point per voxel (the first), as KISS-ICP keeps: centroids would shift with the
// voxel grid, which is fixed in each sweep's own frame, and bias point-to-point residuals.
std::vector<Vec3> FirstPerVoxel(const std::vector<Vec3>& points, double voxel) {
  if (voxel <= 0.0) return points;
  std::unordered_set<uint64_t> seen;
  std::vector<Vec3> out;
  for (const Vec3& p : points) {
    const auto key = [&](int i) { return uint64_t(int64_t(std::floor(p[i] / voxel)) & 0x1FFFFF); };
    if (seen.insert(key(0) | key(1) << 21 | key(2) << 42).second) out.push_back(p);
  }
  return out;
}

}  // namespace

PointIcpResult RegisterPointToPoint(const std::vector<Vec3>& source,
                                    const std::vector<Vec3>& target, const SE3& initial,
                                    const PointIcpOptions& o) {
  const std::vector<Vec3> src = FirstPerVoxel(source, o.source_voxel);
  const KdTree tree(FirstPerVoxel(target, o.target_voxel));
  PointIcpResult result;
  SE3 T = initial;
  std::vector<int> nn;
  std::vector<double> d2;
  for (const double gate : o.gates) {
    for (int it = 0; it < o.iterations; ++it) {
      Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
      Vec6 g = Vec6::Zero();
      int used = 0;
      for (const Vec3& s : src) {
        const Vec3 p = T * s;
        tree.Nearest(p, 1, &nn, &d2);
        if (nn.empty() || d2[0] > gate * gate) continue;
        const Vec3 e = p - tree.points()[nn[0]];
        const double k = o.kernel_absolute > 0.0 ? o.kernel_absolute : o.kernel * gate * gate;
        const double w = k * k / ((k + e.squaredNorm()) * (k + e.squaredNorm()));
        Eigen::Matrix<double, 3, 6> J;
        J << Mat3::Identity(), -so3::Hat(p);
        H += w * J.transpose() * J;
        g += w * J.transpose() * e;
        ++used;
      }
      result.correspondences = used;
      if (used < 6) break;
      if (o.damping > 0.0) H.diagonal() *= 1.0 + o.damping;
      const Vec6 delta = -H.ldlt().solve(g);
      T = SE3::Exp(delta) * T;
      if (delta.norm() < o.converged) break;
    }
  }
  result.target_from_source = T;
  return result;
}

}  // namespace ctlio::eval
