// Unary prior on a full GP knot state x = {T, ϖ, ϖ̇} (SPEC §1–2), e.g. the initial state:
//   r = W·[Log(T·T̄⁻¹); ϖ − ϖ̄; ϖ̇ − ϖ̄̇],  WᵀW = Σ⁻¹ (18×18, may couple the three parts).
// ∂r/∂[δT, δϖ, δϖ̇] = W·blockdiag(J⁻¹(e_T), I, I).
// Parameter blocks: pose (7, PoseManifold), ϖ (6), ϖ̇ (6).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/priors/sqrt_information.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

class StatePrior final : public ceres::SizedCostFunction<18, 7, 6, 6> {
 public:
  using Matrix18 = Eigen::Matrix<double, 18, 18>;

  StatePrior(const SE3& pose, const Vec6& velocity, const Vec6& acceleration,
             const Matrix18& sqrt_information)
      : pose_inv_(pose.Inverse()),
        velocity_(velocity),
        acceleration_(acceleration),
        sqrt_info_(sqrt_information) {}
  static StatePrior* FromCovariance(const SE3& pose, const Vec6& velocity, const Vec6& acceleration,
                                    const Matrix18& covariance) {
    return new StatePrior(pose, velocity, acceleration,
                          SqrtInformationFromCovariance<18>(covariance));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T = PoseManifold::Pose(parameters[0]);
    Eigen::Matrix<double, 18, 1> e;
    e.head<6>() = (T * pose_inv_).Log();
    e.segment<6>(6) = Eigen::Map<const Vec6>(parameters[1]) - velocity_;
    e.tail<6>() = Eigen::Map<const Vec6>(parameters[2]) - acceleration_;
    Eigen::Map<Eigen::Matrix<double, 18, 1>> r(residuals);
    r.noalias() = sqrt_info_ * e;
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      const Eigen::Matrix<double, 18, 6> J =
          sqrt_info_.leftCols<6>() * se3::LeftJacobianInverse(e.head<6>());
      LiftPoseJacobian<18>(J, parameters[0], jacobians[0]);
    }
    using RowMajor18x6 = Eigen::Matrix<double, 18, 6, Eigen::RowMajor>;
    for (int b = 1; b < 3; ++b) {
      if (jacobians[b] == nullptr) continue;
      Eigen::Map<RowMajor18x6> J(jacobians[b]);
      J = sqrt_info_.middleCols<6>(6 * b);
    }
    return true;
  }

 private:
  SE3 pose_inv_;
  Vec6 velocity_, acceleration_;
  Matrix18 sqrt_info_;
};

}  // namespace ctlio
