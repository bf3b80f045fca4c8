// Continuous-time point-to-plane residual with the lidar–IMU extrinsic T_rl as a state (online
// spatial calibration): a point q_l measured in the LIDAR frame at time τ enters as
//
//   e = w · nᵀ (p_ref − T_mr(τ) T_rl q_l),   T_mr(τ) = T_rm(τ)⁻¹,
//
// i.e. ContinuousPointToPlane (continuous_point_to_plane.h: the same interpolation through a
// SharedPoseInterpolation, the same lidar::PointToPlaneError) at the robot-frame point
// q = T_rl q_l. Under the left perturbation T_rl ← Exp(δ)·T_rl (PoseManifold):
// q ← q + [I, −q^]δ and de/dq = −w (C_rm n)ᵀ = −w aᵀ, so
//
//   de/dδ_rl = −w aᵀ [I, −q^] = −w [aᵀ, (q × a)ᵀ] = −de/dδT(τ)
//
// (point_to_plane.h): moving the sensor on the robot by δ is, for this point, the same as moving
// the robot by −δ. The knots get de/dδT(τ) chained as in ContinuousPointToPlane.
// Parameter blocks: pose_k (7, PoseManifold), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1,
// T_rl (7, PoseManifold). The association's point_robot is not read (q is formed from T_rl).
#pragma once

#include <ceres/sized_cost_function.h>

#include <memory>
#include <utility>

#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/factors/lidar/shared_pose_interpolation.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

class ContinuousPointToPlaneExtrinsic final
    : public ceres::SizedCostFunction<1, 7, 6, 6, 7, 6, 6, 7> {
 public:
  // `pose` interpolates at this point's τ (shared by the points of one firing); `point_lidar`
  // is q_l, the point in the lidar frame.
  ContinuousPointToPlaneExtrinsic(std::shared_ptr<const SharedPoseInterpolation> pose,
                                  const PlaneAssociation& association, const Vec3& point_lidar)
      : pose_(std::move(pose)), m_(association), point_lidar_(point_lidar) {}
  ContinuousPointToPlaneExtrinsic(std::shared_ptr<const gp::GpInterpolator> interpolator,
                                  const PlaneAssociation& association, const Vec3& point_lidar)
      : ContinuousPointToPlaneExtrinsic(
            std::make_shared<const SharedPoseInterpolation>(std::move(interpolator)), association,
            point_lidar) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    PlaneAssociation m = m_;
    m.point_robot = PoseManifold::Pose(parameters[6]) * point_lidar_;
    const bool want_rl = jacobians != nullptr && jacobians[6] != nullptr;
    Eigen::Matrix<double, 1, 6> J_tau;
    residuals[0] = ContinuousPointToPlane::EvaluateAtKnots(*pose_, m, parameters, jacobians,
                                                           want_rl ? &J_tau : nullptr);
    if (want_rl) {
      LiftPoseJacobian<1>(Eigen::Matrix<double, 1, 6>(-J_tau), parameters[6], jacobians[6]);
    }
    return true;
  }

  const PlaneAssociation& association() const { return m_; }
  const Vec3& point_lidar() const { return point_lidar_; }
  // A new association of the same point (the next association round of a scan registration),
  // so the residual block stays in the problem instead of being removed and added again.
  // The point in the lidar frame is unchanged (its point_robot is not
  // read). Between solves only: Ceres must not be evaluating this cost function.
  void set_association(const PlaneAssociation& association) { m_ = association; }
  const SharedPoseInterpolation& pose() const { return *pose_; }

 private:
  std::shared_ptr<const SharedPoseInterpolation> pose_;
  PlaneAssociation m_;
  Vec3 point_lidar_;
};

}  // namespace ctlio
