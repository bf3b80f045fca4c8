// Continuous-time point-to-plane residual of one lidar point measured at time τ between two
// knots (SPEC §4):
//
//   e = w · nᵀ (p_ref − T_mr(τ) q),   T_mr(τ) = T_rm(τ)⁻¹,
//
// where T_rm(τ) is the GP interpolation of SPEC §2 between knots k and k+1. The interpolation
// and its Jacobians come from gp::GpInterpolator (the one place that forms a state between
// knots) through a SharedPoseInterpolation, which the points of one firing (same τ) share and a
// window's evaluation callback fills once per evaluation (shared_pose_interpolation.h); this
// factor chains de/dδT(τ) (point_to_plane.h) onto the knots, row first
// (GpInterpolator::ChainPose):
//
//   de/d[δT_k, δϖ_k, δϖ̇_k] = de/dδT(τ) · ∂δT(τ)/∂(knot k)   (1×6 · 6×18), same for k+1.
//
// One residual per point: points sharing a timestamp are NOT summed before squaring (SPEC §4).
// Parameter blocks: pose_k (7, PoseManifold), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1.
// The weight w is part of the association; a robust loss is the caller's choice.
#pragma once

#include <ceres/sized_cost_function.h>

#include <memory>
#include <utility>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/factors/lidar/shared_pose_interpolation.h"

namespace ctlio {

class ContinuousPointToPlane final : public ceres::SizedCostFunction<1, 7, 6, 6, 7, 6, 6> {
 public:
  // `pose` interpolates at this point's τ between the knots' times; the points of one firing
  // share it.
  ContinuousPointToPlane(std::shared_ptr<const SharedPoseInterpolation> pose,
                         const PlaneAssociation& association)
      : pose_(std::move(pose)), m_(association) {}
  // A residual on its own (nothing shared, the interpolation computed at every evaluation).
  ContinuousPointToPlane(std::shared_ptr<const gp::GpInterpolator> interpolator,
                         const PlaneAssociation& association)
      : ContinuousPointToPlane(
            std::make_shared<const SharedPoseInterpolation>(std::move(interpolator)), association) {
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = EvaluateAtKnots(*pose_, m_, parameters, jacobians, nullptr);
    return true;
  }

  // The residual of `m` at the pose `pose` interpolates from the knots (blocks 0–5 of
  // `parameters`) and the knots' Jacobians into blocks 0–5 of `jacobians` (nullable, each
  // block nullable). With J_tau, de/dδT(τ) is also returned, for a factor with further blocks
  // behind the pose (ContinuousPointToPlaneExtrinsic).
  static double EvaluateAtKnots(const SharedPoseInterpolation& pose, const PlaneAssociation& m,
                                double const* const* parameters, double** jacobians,
                                Eigen::Matrix<double, 1, 6>* J_tau) {
    const bool want_k =
        jacobians != nullptr &&
        (jacobians[0] != nullptr || jacobians[1] != nullptr || jacobians[2] != nullptr);
    const bool want_k1 =
        jacobians != nullptr &&
        (jacobians[3] != nullptr || jacobians[4] != nullptr || jacobians[5] != nullptr);
    Eigen::Matrix<double, 1, 18> J_k, J_k1;
    const double e = EvaluateTangent(pose, m, parameters, want_k ? &J_k : nullptr,
                                     want_k1 ? &J_k1 : nullptr, J_tau);
    if (want_k) WriteKnotJacobians(J_k, parameters[0], jacobians);
    if (want_k1) WriteKnotJacobians(J_k1, parameters[3], jacobians + 3);
    return e;
  }

  // The same residual with its Jacobians in the knots' tangent spaces, [δT, δϖ, δϖ̇] of knot k
  // and of knot k+1 (1×18 each, nullable), before EvaluateAtKnots lifts them into the ambient
  // blocks; and de/dδT(τ) (nullable).
  static double EvaluateTangent(const SharedPoseInterpolation& pose, const PlaneAssociation& m,
                                double const* const* parameters, Eigen::Matrix<double, 1, 18>* J_k,
                                Eigen::Matrix<double, 1, 18>* J_k1,
                                Eigen::Matrix<double, 1, 6>* J_tau) {
    const bool chain = J_k != nullptr || J_k1 != nullptr;
    SharedPoseInterpolation::Scratch scratch;
    const SharedPoseInterpolation::Result& x = pose.Pose(parameters, chain, &scratch);
    if (!chain && J_tau == nullptr) return lidar::PointToPlaneError(x.at.T, m, nullptr);
    Eigen::Matrix<double, 1, 6> J;
    const double e = lidar::PointToPlaneError(x.at.T, m, &J);
    if (chain) pose.Chain(x, J, J_k, J_k1);
    if (J_tau != nullptr) *J_tau = J;
    return e;
  }

  const PlaneAssociation& association() const { return m_; }
  const SharedPoseInterpolation& pose() const { return *pose_; }
  // A new association of the same point (the next association round of a scan registration),
  // so the residual block stays in the problem instead of being removed and added again.
  // Between solves only: Ceres must not be evaluating this cost function.
  void set_association(const PlaneAssociation& association) { m_ = association; }

 private:
  // J (1×18) = [pose (tangent), ϖ, ϖ̇] of one knot into its three (nullable) ambient blocks.
  static void WriteKnotJacobians(const Eigen::Matrix<double, 1, 18>& J, const double* pose,
                                 double** out) {
    if (out[0] != nullptr) LiftPoseJacobian<1>(J.leftCols<6>(), pose, out[0]);
    using Row6 = Eigen::Map<Eigen::Matrix<double, 1, 6>>;
    if (out[1] != nullptr) Row6{out[1]} = J.middleCols<6>(6);
    if (out[2] != nullptr) Row6{out[2]} = J.rightCols<6>();
  }

  std::shared_ptr<const SharedPoseInterpolation> pose_;
  PlaneAssociation m_;
};

}  // namespace ctlio
