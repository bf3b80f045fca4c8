// The two pieces every point-to-point registration of ctlio::eval shares (the pairwise ICP of
// point_icp.h and the sweep-to-map odometry of point_odometry.h), written once:
// - the source downsampled to one original point per voxel, as KISS-ICP keeps (centroids would
//   shift with a voxel grid fixed in the sweep's own frame and bias point-to-point residuals);
// - the Gauss–Newton normal equations with KISS-ICP's Geman–McClure weight
//     w = κ² / (κ + |e|²)²   (ρ(e) = ½e²/(κ + e²), κ in m² numerically),
//   accumulated over the correspondences' residuals e and Jacobians ∂e/∂δ.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "ctlio/manifolds/se3.h"

namespace ctlio::eval {

// The first point of each cubic voxel of side `voxel`, in input order; every point if voxel ≤ 0.
std::vector<Vec3> FirstPointPerVoxel(const std::vector<Vec3>& points, double voxel);

class PointToPointSystem {
 public:
  // One correspondence: residual e = p − m and its Jacobian on the 6-vector perturbation δ.
  void Add(const Vec3& e, const Eigen::Matrix<double, 3, 6>& J, double kappa);
  int used() const { return used_; }
  // δ solving (H + μ·diag(H))·δ = −g (μ = damping; 0: Gauss–Newton).
  Vec6 Step(double damping = 0.0) const;

 private:
  Eigen::Matrix<double, 6, 6> H_ = Eigen::Matrix<double, 6, 6>::Zero();
  Vec6 g_ = Vec6::Zero();
  int used_ = 0;
};

}  // namespace ctlio::eval
