// Ceres cost of the IMU-as-input baseline (SPEC §3, Forster et al. 2017):
// one preintegrated IMU interval between navigation states i and j.
//
// Parameter blocks (sizes 7, 3, 6, 7, 3):
//   pose_i, v_i, b_i, pose_j, v_j
// where a pose block stores T_wb = [C_wb, p] (body → world, NOT the
// robot ← map pose of the GP knots) in PoseManifold's layout, v is the
// world-frame velocity and b = [b_a; b_g] the bias over the interval (tie
// b_i to b_j with BiasRandomWalk). Residual, whitened by the preintegrated
// covariance (S = L⁻¹ with Σ = LLᵀ, so SᵀS = Σ⁻¹):
//   e_R = Log(ΔC(b)ᵀ C_iᵀ C_j)
//   e_v = C_iᵀ(v_j − v_i − gΔt) − Δv(b)
//   e_p = C_iᵀ(p_j − p_i − v_iΔt − ½gΔt²) − Δp(b)
//
// Jacobians. PoseManifold perturbs on the left of the WHOLE pose,
// T ← Exp(δ)T with δ = [ρ; φ]: C ← Exp(φ)C and, to first order,
// p ← p + ρ + φ^p. So the position of a pose enters the rotation columns:
//   ∂e_R/∂φ_i = −J_r⁻¹(e_R) C_jᵀ,     ∂e_R/∂φ_j = J_r⁻¹(e_R) C_jᵀ,
//   ∂e_v/∂φ_i = C_iᵀ w^,  w = v_j − v_i − gΔt,
//   ∂e_p/∂ρ_i = −C_iᵀ,    ∂e_p/∂φ_i = C_iᵀ(u + p_i)^,  u = p_j − p_i − v_iΔt − ½gΔt²,
//   ∂e_p/∂ρ_j = C_iᵀ,     ∂e_p/∂φ_j = −C_iᵀ p_j^,
//   ∂e_v/∂v_i = −C_iᵀ, ∂e_p/∂v_i = −C_iᵀΔt, ∂e_v/∂v_j = C_iᵀ,
//   ∂e_R/∂b_g = −J_r⁻¹(e_R) Eᵀ J_r(J_Rg δb_g) J_Rg  (E = Exp(e_R)),
//   ∂[e_v; e_p]/∂b = −[J_v; J_p].
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/imu/preintegrated_imu.h"

namespace ctlio::imu {

class PreintegratedImuFactor final : public ceres::SizedCostFunction<9, 7, 3, 6, 7, 3> {
 public:
  // Copies the preintegration; gravity is the world-frame g (e.g. [0,0,−9.81]).
  // Throws std::invalid_argument if the covariance is not positive definite.
  PreintegratedImuFactor(const PreintegratedImu& preintegrated, const Vec3& gravity);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  const Mat9& sqrt_information() const { return sqrt_information_; }

 private:
  PreintegratedImu pim_;
  Vec3 gravity_;
  Mat9 sqrt_information_;
};

// The interval moved d seconds earlier on the IMU clock, to first order in d: the
// bias-corrected deltas become ΔC → Exp(d·rotation)·ΔC, Δv → Δv + d·velocity, Δp → Δp + d·position
// (preintegrated_imu_time_offset_factor.h derives the rates).
struct PreintegrationShift {
  double d = 0.0;
  Vec3 rotation = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 position = Vec3::Zero();
};

namespace internal {
// The residual and Jacobians of PreintegratedImuFactor (this header) on the blocks pose_i, v_i,
// b_i, pose_j, v_j, with the deltas shifted by `shift` (nullptr: not shifted). d_shift, when not
// nullptr, receives the 9 whitened derivatives of the residual by `shift->d`.
bool EvaluatePreintegrated(const PreintegratedImu& pim, const Vec3& gravity,
                           const Mat9& sqrt_information, const PreintegrationShift* shift,
                           double const* const* parameters, double* residuals, double** jacobians,
                           double* d_shift);
}  // namespace internal

}  // namespace ctlio::imu
