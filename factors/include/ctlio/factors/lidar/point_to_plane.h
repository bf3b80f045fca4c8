// Point-to-plane residual of one lidar point at a single pose (SPEC §4).
//
//   e = w · nᵀ (p_ref − T_mr q),   T_mr = T_rm⁻¹,
//
// q: the point in the robot frame; (n, p_ref): a plane of the map (unit normal
// and a point on it, map frame); w: the caller's weight (e.g. the planarity
// weight of the plane fit). The parameter block is the knot pose T_rm
// (robot←map), 7 doubles with ctlio::PoseManifold, so that this factor and the
// continuous-time one (continuous_point_to_plane.h) use the same state.
// A robust loss, if any, is the caller's choice (ceres::LossFunction).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio {

// The plane a point is associated with: unit normal n and a point p_ref on it (map frame), and
// the weight w of its residual.
struct PlaneAssociation {
  Vec3 point_robot = Vec3::Zero();    // q, robot frame
  Vec3 plane_point = Vec3::Zero();    // p_ref, map frame
  Vec3 plane_normal = Vec3::UnitZ();  // n, map frame, unit length
  double weight = 1.0;                // w
};

namespace lidar {

// e and de/dδ for the pose T_rm under the left perturbation T_rm ← Exp(δ)·T_rm.
// With T_mr ← T_mr·Exp(−δ): d(T_mr q) = −C_mr [I, −q^] δ, so
//   de/dδ = w nᵀ C_mr [I, −q^] = w [aᵀ, (q × a)ᵀ],   a = C_rm n.
// Shared by the single-pose and the continuous-time factor (the latter chains it onto the knots
// through the GP interpolator).
inline double PointToPlaneError(const SE3& T_rm, const PlaneAssociation& m,
                                Eigen::Matrix<double, 1, 6>* J_pose) {
  const Mat3& C_rm = T_rm.rotation();
  const Vec3 p_map = C_rm.transpose() * (m.point_robot - T_rm.translation());
  if (J_pose != nullptr) {
    const Vec3 a = C_rm * m.plane_normal;
    J_pose->leftCols<3>() = m.weight * a.transpose();
    J_pose->rightCols<3>() = m.weight * m.point_robot.cross(a).transpose();
  }
  return m.weight * m.plane_normal.dot(m.plane_point - p_map);
}

}  // namespace lidar

class PointToPlane final : public ceres::SizedCostFunction<1, 7> {
 public:
  explicit PointToPlane(const PlaneAssociation& association) : m_(association) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T_rm = PoseManifold::Pose(parameters[0]);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Matrix<double, 1, 6> J;
      residuals[0] = lidar::PointToPlaneError(T_rm, m_, &J);
      LiftPoseJacobian<1>(J, parameters[0], jacobians[0]);
    } else {
      residuals[0] = lidar::PointToPlaneError(T_rm, m_, nullptr);
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
