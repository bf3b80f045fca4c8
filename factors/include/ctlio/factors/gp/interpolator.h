// GP interpolation of the SE(3) state between two knots, and extrapolation past the last
// knot (SPEC §2). The ONLY place that knows how a state between knots is formed: lidar and IMU
// factors at a time τ hold a GpInterpolator and chain its Jacobians onto the knots.
//
//   Ω = Q(τ−t_k)Φ(t_{k+1}−τ)ᵀQ(T)⁻¹,  Λ = Φ(τ−t_k) − ΩΦ(T)   (per axis; Qc cancels)
//   γ(τ) = Λγ_k + Ωγ_{k+1} = [ξ; ξ̇; ξ̈],  γ_k, γ_{k+1} from knot_state.h
//   T(τ) = Exp(ξ)T_k,  ϖ(τ) = J(ξ)ξ̇,  ϖ̇(τ) = J(ξ)(ξ̈ + ½ξ̇^⋏ϖ(τ)).
// Extrapolation: γ(τ) = Φ(τ−t_k)γ_k.
//
// Jacobians (left perturbations; rows [δT; δϖ; δϖ̇] at τ, columns [δT, δϖ, δϖ̇] of a knot):
//   δT(τ) = J dξ + Ad(Exp ξ)δT_k,
//   dϖ(τ) = ∂(Jξ̇)/∂ξ dξ + J dξ̇,
//   dϖ̇(τ) = [∂(Jv)/∂ξ + ½Jξ̇^⋏∂(Jξ̇)/∂ξ] dξ + ½J(ξ̇^⋏J − ϖ(τ)^⋏) dξ̇ + J dξ̈,  v = ξ̈ + ½ξ̇^⋏ϖ,
// and dγ(τ) = Λdγ_k + Ωdγ_{k+1}. All exact (checked against numeric differentiation).
//
// Time derivative (for a measurement whose time τ = t + δ depends on an estimated clock offset δ):
// with A the per-axis Singer drift [[0, 1, 0], [0, 0, 1], [0, 0, −α]] and, Qc = 1 since it
// cancels, dΦ(τ−t_k)/dτ = AΦ, dQ(τ−t_k)/dτ = AQ + QAᵀ + e₃e₃ᵀ, dΦ(t_{k+1}−τ)/dτ = −Φ(t_{k+1}−τ)A:
//   Ω' = AΩ + e₃e₃ᵀΦ(t_{k+1}−τ)ᵀQ(T)⁻¹,  Λ' = AΦ(τ−t_k) − Ω'Φ(T),
// so dγ(τ)/dτ = Λ'γ_k + Ω'γ_{k+1} = [ξ̇; ξ̈; ξ⃛] (the first two rows are γ's own, the third the
// posterior mean of the jerk). The state's rate in the tangent [δT; δϖ; δϖ̇] of x(τ) is the
// chain above applied to this variation: ẋ(τ) = M·dγ/dτ with M = [[J, 0, 0], [M21, J, 0],
// [M31, M32, J]] (its pose rows are Jξ̇ = ϖ(τ), T(τ+h) ≈ Exp(hϖ)T(τ)).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"

namespace ctlio::gp {

using PoseJacobian = Eigen::Matrix<double, 6, 18>;
using StateJacobian = Eigen::Matrix<double, 18, 18>;

// Row blocks of a StateJacobian (3 rows each, rows [δρ; δφ; ϖ_v; ϖ_ω; ϖ̇_v; ϖ̇_ω]), combined with
// |, for GpInterpolator::StateRows: a factor that reads a few components of the state asks for
// those rows only (gyro: ϖ_ω; accelerometer: δφ, ϖ̇_v and, for the exact specific force, ϖ).
enum StateRowBlock : unsigned {
  kTranslationRows = 1u << 0,
  kRotationRows = 1u << 1,
  kLinearVelocityRows = 1u << 2,
  kAngularVelocityRows = 1u << 3,
  kLinearAccelerationRows = 1u << 4,
  kAngularAccelerationRows = 1u << 5,
  kAllStateRows = (1u << 6) - 1,
};

using StateRate = Eigen::Matrix<double, 18, 1>;

class GpInterpolator {
 public:
  // Precomputes Λ(τ), Ω(τ), and with `with_time_derivative` also Λ'(τ), Ω'(τ) (header) for
  // StateRows' `rate`. Requires t_k < t_k1 and t_k ≤ tau ≤ t_k1 (throws otherwise).
  GpInterpolator(const SingerModel<6>& model, double t_k, double t_k1, double tau,
                 bool with_time_derivative = false);

  // T(τ) and ∂δT(τ)/∂[δT, δϖ, δϖ̇] of each knot (6×18); any output may be null.
  void Pose(const KnotState& k, const KnotState& k1, SE3* T, PoseJacobian* J_k,
            PoseJacobian* J_k1) const;
  // T(τ), ϖ(τ), ϖ̇(τ) and the 18×18 Jacobians onto each knot; any output may be null.
  void State(const KnotState& k, const KnotState& k1, KnotState* x, StateJacobian* J_k,
             StateJacobian* J_k1) const;
  // As State, but only the row blocks selected by `rows` (StateRowBlock flags) of J_k and J_k1
  // are written; the other rows are left as they were. Same values as the rows of State() up to
  // rounding (the chain is associated per row, (Σ_c B_c P_c)·J⁻¹ with B_c = M[rows]·Ω_{·c}, so
  // a 3-row request costs a fraction of the 18×18 product), checked in interpolator_test.
  void StateRows(const KnotState& k, const KnotState& k1, unsigned rows, KnotState* x,
                 StateJacobian* J_k, StateJacobian* J_k1) const;

  // Pose and StateRows with knot k+1 given by the interval's local variables γ_{k+1} and their
  // Jacobians, formed once for every interpolation between the same two knots
  // (`local` = LocalVariables(k, k1, true); gp/shared_knot_interval.h). Bit-identical to the
  // overloads above, which form them per call.
  void Pose(const KnotState& k, const LocalVariables& local, SE3* T, PoseJacobian* J_k,
            PoseJacobian* J_k1) const;
  void StateRows(const KnotState& k, const LocalVariables& local, unsigned rows, KnotState* x,
                 StateJacobian* J_k, StateJacobian* J_k1) const;
  // As StateRows, and the rows `rows` of the state's time derivative ẋ(τ) = d[δT; δϖ; δϖ̇]/dτ
  // (header) into *rate (other rows left as they were). Requires with_time_derivative.
  void StateRows(const KnotState& k, const KnotState& k1, unsigned rows, KnotState* x,
                 StateJacobian* J_k, StateJacobian* J_k1, StateRate* rate) const;

  // For residuals that read T(τ) through a row vector u = ∂e/∂δT(τ) (a point-to-plane error):
  // u·∂δT(τ)/∂knot costs a few 1×6 products when chained row-first,
  //   u·∂δT/∂δT_{k+1} = Σ_c (v∘Ω_0c)·P_c,  v = u·J(ξ),  P = [J⁻¹, D1·J⁻¹, D2·J⁻¹],
  //   u·∂δT/∂ϖ_{k+1} = (v∘Ω_01)·J⁻¹ + (v∘Ω_02)·E,  u·∂δT/∂ϖ̇_{k+1} = (v∘Ω_02)·J⁻¹,
  //   u·∂δT/∂δT_k = −(u·∂δT/∂δT_{k+1})·Ad21 + u·Ad(Exp ξ),  u·∂δT/∂ϖ_k = v∘Λ_01,
  //   u·∂δT/∂ϖ̇_k = v∘Λ_02
  // (the rows of Pose()'s Jacobians, associated per row; equal up to rounding, tested), where
  // Pose() forms the 6×18 matrices (~6 dense 6×6 products) that pay only when many residuals
  // share one τ. PoseAtTau holds the τ-dependent factors.
  struct PoseAtTau {
    SE3 T;    // T(τ), bit-identical to Pose()
    Mat6 J;   // J(ξ)
    Mat6 Ad;  // Ad(Exp ξ)
  };
  // `local`: LocalVariables(k, k1, with_jacobians) with AddChainProducts() for ChainPose.
  void PoseAt(const KnotState& k, const LocalVariables& local, PoseAtTau* out) const;
  // u·∂δT(τ)/∂[δT, δϖ, δϖ̇] of knot k and of knot k+1 (each 1×18; either may be null).
  void ChainPose(const PoseAtTau& at, const LocalVariables& local,
                 const Eigen::Matrix<double, 1, 6>& u, Eigen::Matrix<double, 1, 18>* J_k,
                 Eigen::Matrix<double, 1, 18>* J_k1) const;

  const AxisBlockMatrix<6>& Lambda() const { return lambda_; }
  const AxisBlockMatrix<6>& Omega() const { return omega_; }
  // Λ'(τ), Ω'(τ); requires with_time_derivative.
  const AxisBlockMatrix<6>& LambdaDot() const { return rates_->lambda_dot; }
  const AxisBlockMatrix<6>& OmegaDot() const { return rates_->omega_dot; }

 private:
  struct Rates {
    AxisBlockMatrix<6> lambda_dot, omega_dot;
  };
  AxisBlockMatrix<6> lambda_, omega_;
  std::shared_ptr<const Rates> rates_;  // only with_time_derivative (keeps the default small)
};

// Prediction past the last knot k: γ(τ) = Φ(τ−t_k)γ_k (the GP mean given x_k only).
class GpExtrapolator {
 public:
  // Requires tau ≥ t_k (throws otherwise).
  GpExtrapolator(const SingerModel<6>& model, double t_k, double tau);

  void Pose(const KnotState& k, SE3* T, PoseJacobian* J_k) const;
  void State(const KnotState& k, KnotState* x, StateJacobian* J_k) const;

  const AxisBlockMatrix<6>& Transition() const { return phi_; }

 private:
  AxisBlockMatrix<6> phi_;
};

}  // namespace ctlio::gp
