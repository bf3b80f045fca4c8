// Unary prior on a pose: r = W·Log(T·T̄⁻¹) (left perturbation, SPEC §1), WᵀW = Σ⁻¹.
// T ← Exp(δ)T gives Log(Exp(δ)TT̄⁻¹) ≈ e + J⁻¹(e)δ, so ∂r/∂δ = W·J⁻¹(e) exactly (not the
// identity: the prior stays correct far from T̄). Parameter block: pose (7, PoseManifold).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/priors/sqrt_information.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

class PosePrior final : public ceres::SizedCostFunction<6, 7> {
 public:
  PosePrior(const SE3& mean, const Mat6& sqrt_information)
      : mean_inv_(mean.Inverse()), sqrt_info_(sqrt_information) {}
  static PosePrior* FromCovariance(const SE3& mean, const Mat6& covariance) {
    return new PosePrior(mean, SqrtInformationFromCovariance<6>(covariance));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T = PoseManifold::Pose(parameters[0]);
    const Vec6 e = (T * mean_inv_).Log();
    Eigen::Map<Vec6> r(residuals);
    r.noalias() = sqrt_info_ * e;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      const Mat6 J = sqrt_info_ * se3::LeftJacobianInverse(e);
      LiftPoseJacobian<6>(J, parameters[0], jacobians[0]);
    }
    return true;
  }

 private:
  SE3 mean_inv_;
  Mat6 sqrt_info_;
};

}  // namespace ctlio
