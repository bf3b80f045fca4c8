// Small pieces both LIO pipelines share: the robust loss and solver options of the window, the
// point-to-plane residual on a body→world pose block (the baseline's T_wb, whereas
// ctlio::PointToPlane takes the GP knots' T_rm; only the pose parametrisation differs, the
// error is lidar::PointToPlaneError's), and the bias random walk from the config.
#pragma once

#include <ceres/loss_function.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <cstring>
#include <memory>
#include <mutex>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// The front end's loss (cauchy/huber/none, scale in metres), applied to the residual divided by
// config.frontend.point_noise_sigma, hence scaled by the same factor. nullptr for "none".
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

// The interpolated pose T_rm(τ) and its Jacobians onto both knots (gp::GpInterpolator::Pose), for
// all the points of a scan that share the time τ (the points of one lidar firing). Ceres
// evaluates every residual block at the same parameter values, so the interpolation is done once
// per firing instead of once per point: the first residual of a firing computes it, the others
// find the same 38 knot values and reuse it. This is the dominant cost of a scan (SPEC §4 keeps
// one residual per point, each with its own robust loss; only the shared work is shared).
// Thread-safe (a mutex guards the cache; outputs are copied out).
class SharedInterpolatedPose {
 public:
  SharedInterpolatedPose(const gp::SingerModel<6>& model, double t_k, double t_k1, double tau)
      : interpolator_(model, t_k, t_k1, tau) {}

  // parameters: pose_k, ϖ_k, ϖ̇_k, pose_k1, ϖ_k1, ϖ̇_k1. J_k, J_k1 may be null.
  void Pose(double const* const* parameters, SE3* T, gp::PoseJacobian* J_k,
            gp::PoseJacobian* J_k1) const {
    double key[kKeySize];
    const int sizes[6] = {7, 6, 6, 7, 6, 6};
    for (int b = 0, o = 0; b < 6; o += sizes[b], ++b) {
      std::memcpy(key + o, parameters[b], sizes[b] * sizeof(double));
    }
    std::lock_guard<std::mutex> lock(mutex_);
    // A miss always computes the Jacobians too: the trust-region minimiser evaluates the cost at
    // a candidate point and, when the step succeeds, the Jacobians at that same point, which then
    // hit the cache instead of redoing the interpolation (the pose is the same either way).
    if (!valid_ || std::memcmp(key, key_, sizeof(key)) != 0) {
      const gp::KnotState k = gp::ReadKnotState(parameters[0], parameters[1], parameters[2]);
      const gp::KnotState k1 = gp::ReadKnotState(parameters[3], parameters[4], parameters[5]);
      interpolator_.Pose(k, k1, &T_, &J_k_, &J_k1_);
      std::memcpy(key_, key, sizeof(key));
      valid_ = true;
    }
    *T = T_;
    if (J_k != nullptr) *J_k = J_k_;
    if (J_k1 != nullptr) *J_k1 = J_k1_;
  }

 private:
  static constexpr int kKeySize = 38;
  gp::GpInterpolator interpolator_;
  mutable std::mutex mutex_;
  mutable double key_[kKeySize] = {};
  mutable bool valid_ = false;
  mutable SE3 T_;
  mutable gp::PoseJacobian J_k_, J_k1_;
};

// ctlio::ContinuousPointToPlane's residual and Jacobians (e = w nᵀ(p_ref − T_rm(τ)⁻¹q), chained
// onto both knots' pose/ϖ/ϖ̇), with the interpolation shared by the points of one firing.
class FiringPointToPlane final : public ceres::SizedCostFunction<1, 7, 6, 6, 7, 6, 6> {
 public:
  FiringPointToPlane(std::shared_ptr<const SharedInterpolatedPose> pose, const PlaneAssociation& a)
      : pose_(std::move(pose)), a_(a) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const bool want_k = jacobians != nullptr && (jacobians[0] || jacobians[1] || jacobians[2]);
    const bool want_k1 = jacobians != nullptr && (jacobians[3] || jacobians[4] || jacobians[5]);
    SE3 T;
    if (!want_k && !want_k1) {
      pose_->Pose(parameters, &T, nullptr, nullptr);
      residuals[0] = lidar::PointToPlaneError(T, a_, nullptr);
      return true;
    }
    gp::PoseJacobian J_k, J_k1;
    pose_->Pose(parameters, &T, &J_k, &J_k1);
    Eigen::Matrix<double, 1, 6> J_tau;
    residuals[0] = lidar::PointToPlaneError(T, a_, &J_tau);
    if (want_k) Write(J_tau * J_k, parameters[0], jacobians);
    if (want_k1) Write(J_tau * J_k1, parameters[3], jacobians + 3);
    return true;
  }

 private:
  static void Write(const Eigen::Matrix<double, 1, 18>& J, const double* pose, double** out) {
    if (out[0] != nullptr) LiftPoseJacobian<1>(J.leftCols<6>(), pose, out[0]);
    if (out[1] != nullptr) Eigen::Map<Eigen::Matrix<double, 1, 6>>{out[1]} = J.middleCols<6>(6);
    if (out[2] != nullptr) Eigen::Map<Eigen::Matrix<double, 1, 6>>{out[2]} = J.rightCols<6>();
  }

  std::shared_ptr<const SharedInterpolatedPose> pose_;
  PlaneAssociation a_;
};

// imu::BiasRandomWalk between knots dt apart with the config's walk variances (given per
// bias_walk_period seconds, scaled by Δt: SPEC §3).
ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt);

}  // namespace ctlio::lio
