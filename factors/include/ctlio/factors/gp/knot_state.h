// The GP trajectory state of one knot on SE(3) (SPEC §1–2) and the local variables
// γ_{k+1} that the prior factor and the interpolator both use (written once, here).
#pragma once

#include "ctlio/factors/gp/se3_jacobian_derivative.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio::gp {

// T_k (robot←map), ϖ_k (minus the body twist, in the robot frame, [ρ; φ] order) and ϖ̇_k.
struct KnotState {
  SE3 pose;
  Vec6 velocity = Vec6::Zero();
  Vec6 acceleration = Vec6::Zero();
};

// Reads a knot from its three Ceres parameter blocks (pose: 7 doubles in PoseManifold
// storage; velocity and acceleration: 6 doubles each).
inline KnotState ReadKnotState(const double* pose, const double* velocity,
                               const double* acceleration) {
  KnotState s;
  s.pose = PoseManifold::Pose(pose);
  s.velocity = Eigen::Map<const Vec6>(velocity);
  s.acceleration = Eigen::Map<const Vec6>(acceleration);
  return s;
}

// γ_{k+1} = [ξ21; J⁻¹ϖ_{k+1}; ½ϖ_{k+1}^⋏J⁻¹ϖ_{k+1} + J⁻¹ϖ̇_{k+1}], ξ21 = log(T_{k+1}T_k⁻¹),
// J = J(ξ21) (SPEC §2; −½(J⁻¹ϖ)^⋏ϖ = ½ϖ^⋏J⁻¹ϖ). γ_k = [0; ϖ_k; ϖ̇_k] needs no code.
// With jacobians:
//   ∂γ_{k+1}/∂δT_{k+1} = [I; D1; D2]·J⁻¹,  ∂γ_{k+1}/∂δT_k = −[I; D1; D2]·J⁻¹·Ad(T21)
//   (ξ21 ← ξ21 + J⁻¹δ for T_{k+1} ← Exp(δ)T_{k+1}; T21 ← T21·Exp(−δ) for T_k),
//   ∂γ_{k+1}/∂ϖ_{k+1} = [0; J⁻¹; E],  ∂γ_{k+1}/∂ϖ̇_{k+1} = [0; 0; J⁻¹],
// with D1 = ∂(J⁻¹ϖ)/∂ξ, D2 = ½ϖ^⋏D1 + ∂(J⁻¹ϖ̇)/∂ξ, E = ½(ϖ^⋏J⁻¹ − (J⁻¹ϖ)^⋏).
struct LocalVariables {
  Vec6 gamma[3];  // γ_{k+1}
  Mat6 J_inv;     // J⁻¹(ξ21)
  // Filled only when requested:
  Mat6 D1, D2, E;
  Mat6 Ad21;  // Ad(T_{k+1}T_k⁻¹)

  LocalVariables(const KnotState& k, const KnotState& k1, bool with_jacobians) {
    const SE3 T21 = k1.pose * k.pose.Inverse();
    const Vec6 xi = T21.Log();
    J_inv = se3::LeftJacobianInverse(xi);
    const Vec6& w = k1.velocity;
    gamma[0] = xi;
    gamma[1].noalias() = J_inv * w;
    const Vec6 u2 = J_inv * k1.acceleration;
    gamma[2] = 0.5 * CurlyHatTimes(w, gamma[1]) + u2;
    if (!with_jacobians) return;
    // ∂(J⁻¹w)/∂ξ = −J⁻¹·∂(Ju)/∂ξ|_{u=J⁻¹w} (se3_jacobian_derivative.h); u = γ2, u2 here.
    const Vec6 us[2] = {gamma[1], u2};
    Mat6 DJ[2];
    LeftJacobianVectorDerivatives<2>(xi, us, DJ);
    D1.noalias() = -J_inv * DJ[0];
    D2.noalias() = -J_inv * DJ[1];
    D2 += 0.5 * CurlyHatTimes(w, D1);
    E = 0.5 * (CurlyHatTimes(w, J_inv) - se3::CurlyHat(gamma[1]));
    Ad21 = T21.Adjoint();
  }

  // D1·J⁻¹ and D2·J⁻¹ (∂γ_{k+1}/∂δT_{k+1} = [I; D1; D2]·J⁻¹), which chaining row vectors
  // through the interpolation reads (GpInterpolator::ChainPose); formed once per interval by
  // gp/shared_knot_interval.h. Requires with_jacobians.
  Mat6 DJ1, DJ2;
  void AddChainProducts() {
    DJ1.noalias() = D1 * J_inv;
    DJ2.noalias() = D2 * J_inv;
  }
};

}  // namespace ctlio::gp
