// Small pieces both LIO pipelines share that no factor library provides (yet): the robust loss
// and solver options of the window, the point-to-plane residual on a body→world pose block
// (the baseline's T_wb, whereas ctlio::PointToPlane takes the GP knots' T_rm), and the bias
// random walk between two bias blocks.
#pragma once

#include <ceres/loss_function.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <memory>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// The front end's loss (cauchy/huber/none, scale in metres), applied to the residual divided by
// config.point_to_plane_std, hence scaled by the same factor. nullptr for "none".
std::unique_ptr<ceres::LossFunction> MakeLidarLoss(const OdometryConfig& config);

// Dense normal Cholesky: a window of two or three knots has < 60 tangent parameters, where the
// dense factorisation beats SuiteSparse's symbolic overhead.
ceres::Solver::Options WindowSolverOptions(const OdometryConfig& config);

// e = w nᵀ(p_ref − T_wb q) on a pose block holding T_wb (body → world), left perturbation
// T_wb ← Exp(δ)T_wb: d(T_wb q)/dδ = [I, −(T_wb q)^] (se3::PointJacobian), so
// de/dδ = −w nᵀ [I, −(T_wb q)^].
class PointToPlaneWorld final : public ceres::SizedCostFunction<1, 7> {
 public:
  explicit PointToPlaneWorld(const PlaneAssociation& a) : a_(a) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T_wb = PoseManifold::Pose(parameters[0]);
    const Vec3 p = T_wb * a_.point_robot;
    residuals[0] = a_.weight * a_.plane_normal.dot(a_.plane_point - p);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      const Eigen::Matrix<double, 1, 6> J =
          -a_.weight * a_.plane_normal.transpose() * se3::PointJacobian(p);
      LiftPoseJacobian<1>(J, parameters[0], jacobians[0]);
    }
    return true;
  }

 private:
  PlaneAssociation a_;
};

// Bias random walk between knots dt apart (SPEC §3): e = S(b_j − b_i) with S = Σ^{-1/2},
// Σ = diag(σ_a², σ_a², σ_a², σ_g², …)·dt/bias_walk_period — scaled by Δt, unlike the reference.
ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt);

}  // namespace ctlio::lio
