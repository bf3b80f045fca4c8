// A measured position of the body (e.g. a motion-capture or GNSS fix) on a pose block:
//   r = W·(p(T) − p_m),  WᵀW = Σ⁻¹ (3×3),
// where p(T) is the body's position in the world/map frame. Which translation that is depends on
// the pose convention of the block (SPEC §1):
//   kWorldFromBody (T = T_wb, e.g. the navigation states of preintegration): p = r_wb, and the
//     left perturbation T ← Exp(δ)T, δ = [ρ; φ], moves it to p + ρ + φ^p:  ∂p/∂δ = [I, −p^];
//   kBodyFromWorld (T = T_rm, the GP knots): p = translation of T⁻¹ = −C_rmᵀ r_rm, and
//     (Exp(δ)T)⁻¹ = T⁻¹Exp(−δ) moves it to p − C_mr ρ:  ∂p/∂δ = [−C_mr, 0].
// Both are exact (no small-angle approximation), so the factor is correct far from p_m.
// Parameter block: pose (7, PoseManifold).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/priors/sqrt_information.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

enum class PoseConvention { kWorldFromBody, kBodyFromWorld };

class PositionMeasurement final : public ceres::SizedCostFunction<3, 7> {
 public:
  PositionMeasurement(const Vec3& measured, const Mat3& covariance, PoseConvention convention)
      : measured_(measured),
        sqrt_info_(SqrtInformationFromCovariance<3>(covariance, "PositionMeasurement")),
        convention_(convention) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T = PoseManifold::Pose(parameters[0]);
    const bool world_from_body = convention_ == PoseConvention::kWorldFromBody;
    const Vec3 p = world_from_body ? Vec3(T.translation()) : Vec3(T.Inverse().translation());
    Eigen::Map<Vec3>{residuals} = sqrt_info_ * (p - measured_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Matrix<double, 3, 6> dp;
      if (world_from_body) {
        dp << Mat3::Identity(), -so3::Hat(p);
      } else {
        dp << -T.rotation().transpose(), Mat3::Zero();
      }
      LiftPoseJacobian<3>(sqrt_info_ * dp, parameters[0], jacobians[0]);
    }
    return true;
  }

 private:
  Vec3 measured_;
  Mat3 sqrt_info_;
  PoseConvention convention_;
};

}  // namespace ctlio
