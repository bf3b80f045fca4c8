#include "ctlio/eval/point_icp.h"

#include "ctlio/eval/geometry_statistics.h"
#include "ctlio/eval/point_to_point.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::eval {

PointIcpResult RegisterPointToPoint(const std::vector<Vec3>& source,
                                    const std::vector<Vec3>& target, const SE3& initial,
                                    const PointIcpOptions& o) {
  const std::vector<Vec3> src = FirstPointPerVoxel(source, o.source_voxel);
  const KdTree tree(FirstPointPerVoxel(target, o.target_voxel));
  PointIcpResult result;
  SE3 T = initial;
  std::vector<int> nn;
  std::vector<double> d2;
  for (const double gate : o.gates) {
    for (int it = 0; it < o.iterations; ++it) {
      PointToPointSystem system;
      for (const Vec3& s : src) {
        const Vec3 p = T * s;
        tree.Nearest(p, 1, &nn, &d2);
        if (nn.empty() || d2[0] > gate * gate) continue;
        const Vec3 e = p - tree.points()[nn[0]];
        Eigen::Matrix<double, 3, 6> J;
        J << Mat3::Identity(), -so3::Hat(p);
        system.Add(e, J, o.kernel_absolute > 0.0 ? o.kernel_absolute : o.kernel * gate * gate);
      }
      result.correspondences = system.used();
      if (system.used() < 6) break;
      const Vec6 delta = system.Step(o.damping);
      T = SE3::Exp(delta) * T;
      if (delta.norm() < o.converged) break;
    }
  }
  result.target_from_source = T;
  return result;
}

}  // namespace ctlio::eval
