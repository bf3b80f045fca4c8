// Binary GP motion prior between consecutive SE(3) knots (SPEC §2):
//   e = γ_{k+1} − Φ(Δt)γ_k,  residual r = W·e,  WᵀW = Q(Δt)⁻¹,
// γ_k = [0; ϖ_k; ϖ̇_k], γ_{k+1} = [ξ21; J⁻¹ϖ_{k+1}; −½(J⁻¹ϖ_{k+1})^⋏ϖ_{k+1} + J⁻¹ϖ̇_{k+1}]
// (knot_state.h). WNOJ is α = 0, Singer α > 0, per axis of SingerModel<6> ([ρ; φ] order).
// The Jacobian is taken through the SAME Φ(Δt) as the error (the reference code uses the WNOJ Φ
// in its Singer Jacobian) and through the exact derivatives of J⁻¹(ξ21) (no small-ξ
// approximation), so it passes tight numeric checks at any rotation.
// Parameter blocks: pose_k (7), ϖ_k (6), ϖ̇_k (6), pose_k+1 (7), ϖ_k+1 (6), ϖ̇_k+1 (6).
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"

namespace ctlio::gp {

class SingerPrior final : public ceres::SizedCostFunction<18, 7, 6, 6, 7, 6, 6> {
 public:
  using Vector18 = Eigen::Matrix<double, 18, 1>;

  // dt = t_{k+1} − t_k > 0 (throws otherwise).
  SingerPrior(const SingerModel<6>& model, double dt);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The unwhitened error e = γ_{k+1} − Φγ_k (for tests, the marginaliser and diagnostics).
  Vector18 Error(const KnotState& k, const KnotState& k1) const;

  const AxisBlockMatrix<6>& Transition() const { return phi_; }
  const AxisBlockMatrix<6>& SqrtInformation() const { return sqrt_info_; }

 private:
  AxisBlockMatrix<6> phi_;        // Φ(Δt)
  AxisBlockMatrix<6> sqrt_info_;  // W, block lower triangular
  AxisBlockMatrix<6> w_phi_;      // W·Φ
};

}  // namespace ctlio::gp
