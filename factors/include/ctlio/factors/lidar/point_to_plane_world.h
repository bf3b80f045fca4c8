// Point-to-plane residual of one lidar point at a body→world pose (SPEC §4), the
// parametrisation of navigation states (the IMU-as-input baseline's T_wb, SPEC §6):
//
//   e = w · nᵀ (p_ref − T_wb q).
//
// Same error as PointToPlane (point_to_plane.h), which takes the GP knots' T_rm = T_wb⁻¹; only
// the pose block differs. Left perturbation T_wb ← Exp(δ)·T_wb: d(T_wb q)/dδ = [I, −(T_wb q)^]
// (se3::PointJacobian), so de/dδ = −w nᵀ [I, −(T_wb q)^].
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio {

class PointToPlaneWorld final : public ceres::SizedCostFunction<1, 7> {
 public:
  explicit PointToPlaneWorld(const PlaneAssociation& association) : m_(association) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T_wb = PoseManifold::Pose(parameters[0]);
    const Vec3 p = T_wb * m_.point_robot;
    residuals[0] = m_.weight * m_.plane_normal.dot(m_.plane_point - p);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      const Eigen::Matrix<double, 1, 6> J =
          -m_.weight * m_.plane_normal.transpose() * se3::PointJacobian(p);
      LiftPoseJacobian<1>(J, parameters[0], jacobians[0]);
    }
    return true;
  }

  const PlaneAssociation& association() const { return m_; }
  // A new association of the same point (the next association round of a scan registration),
  // so the residual block stays in the problem instead of being removed and added again.
  // Between solves only: Ceres must not be evaluating this cost function.
  void set_association(const PlaneAssociation& association) { m_ = association; }

 private:
  PlaneAssociation m_;
};

}  // namespace ctlio
