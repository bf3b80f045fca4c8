// IMU as an input: on-manifold preintegration (Forster, Carlone, Dellaert,
// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial
// Odometry", TRO 2017), SPEC §3.
//
// Navigation state of the baseline: {C, p, v, b} with C = C_wb (body → world),
// p the body position in the world, v its world-frame velocity, and the bias
// b = [b_a; b_g] (accelerometer first, as everywhere in ctlio, SPEC §1). The
// IMU measures ω_m = ω + b_g + n_g and a_m = C_wbᵀ(p̈ − g) + b_a + n_a in its
// sensor frame s; an optional rotation C_bs maps sensor into body axes (the
// biases and noise stay sensor-frame quantities).
//
// Between two states i, j the preintegrated quantities, evaluated at the bias
// estimate b̄ used while integrating, are
//   ΔC = Π Exp(ω̂_k Δt_k),  Δv = Σ ΔC_k ∫Exp(ω̂_k τ)dτ â_k,  Δp = ...,
// with ω̂ = C_bs(ω_m − b̄_g), â = C_bs(a_m − b̄_a). Forster's Euler step uses
// ΔC_k â_k Δt for the velocity increment; here each step is integrated EXACTLY
// for a measurement held constant in the body frame over Δt_k:
//   Δv ← Δv + ΔC_k J(φ) â Δt,   Δp ← Δp + Δv Δt + ΔC_k H(φ) â Δt²,   φ = ω̂Δt,
// J the SO(3) left Jacobian ∫₀¹Exp(αφ)dα and H(φ) = ∫₀¹(1−α)Exp(αφ)dα. This
// makes a constant-twist motion exact at any rate; Forster's step is the
// φ → 0 limit (J, H → I, ½I).
//
// Errors are Forster's: ΔC = ΔC̄·Exp(δφ), Δv = Δv̄ + δv, Δp = Δp̄ + δp, ordered
// [δφ; δv; δp] in the 9×9 covariance and in the residual. The covariance is
// propagated sample by sample from the continuous noise densities (discrete
// variance σ²/Δt per sample), and the first-order bias Jacobians by the same
// linearised step, so that
//   ΔC(b) ≈ ΔC̄·Exp(J_Rg δb_g),  Δv(b) ≈ Δv̄ + J_va δb_a + J_vg δb_g,
//   Δp(b) ≈ Δp̄ + J_pa δb_a + J_pg δb_g,     δb = b − b̄.
#pragma once

#include <Eigen/Core>

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/so3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat96 = Eigen::Matrix<double, 9, 6>;

// Continuous-time white-noise densities of the IMU (the datasheet's "noise
// density"): σ_g in rad/s/√Hz, σ_a in m/s²/√Hz.
struct ImuNoise {
  double gyro_noise_density = 0.0;
  double accel_noise_density = 0.0;
  // Optional extra random walk on the preintegrated position, variance per
  // second per axis (GTSAM's "integration covariance"; 0 = Forster's model).
  double integration_variance = 0.0;
};

// Body → world navigation state of the IMU-as-input baseline.
struct NavState {
  Mat3 C = Mat3::Identity();  // C_wb
  Vec3 p = Vec3::Zero();      // position of the body in the world
  Vec3 v = Vec3::Zero();      // world-frame velocity
};

// H(φ) = ∫₀¹(1−α)Exp(αφ)dα = Σₙ (φ^)ⁿ/(n+2)! = ½I + c·φ^ + e·φ^φ^, with
// c = (θ − sinθ)/θ³ (so3::RodriguesCoefficients) and e = (θ² + 2cosθ − 2)/(2θ⁴)
// (so3::RodriguesCoefficientE).
Mat3 DoubleIntegralJacobian(const Vec3& phi);

class PreintegratedImu {
 public:
  // bias_hat = b̄ = [b_a; b_g], the linearisation point of the bias.
  PreintegratedImu(const Vec6& bias_hat, const ImuNoise& noise,
                   const Mat3& C_body_sensor = Mat3::Identity());

  // Adds one sample held constant over dt > 0 seconds (sensor frame, raw:
  // the bias b̄ is removed here). Throws std::invalid_argument if dt ≤ 0 or
  // the sample is not finite.
  void Integrate(const Vec3& accel, const Vec3& gyro, double dt);

  // Restarts from ΔC = I, Δv = Δp = 0 with a new bias estimate.
  void Reset(const Vec6& bias_hat);

  double delta_t() const { return delta_t_; }
  const Mat3& delta_rotation() const { return delta_C_; }
  const Vec3& delta_velocity() const { return delta_v_; }
  const Vec3& delta_position() const { return delta_p_; }
  const Vec6& bias_hat() const { return bias_hat_; }
  const Mat3& C_body_sensor() const { return C_bs_; }
  // 9×9 covariance of [δφ; δv; δp].
  const Mat9& covariance() const { return covariance_; }
  // d[δφ; δv; δp]/d[b_a; b_g] at b̄ (columns accel bias first).
  const Mat96& bias_jacobian() const { return bias_jacobian_; }
  Mat3 dR_dbg() const { return bias_jacobian_.block<3, 3>(0, 3); }
  Mat3 dv_dba() const { return bias_jacobian_.block<3, 3>(3, 0); }
  Mat3 dv_dbg() const { return bias_jacobian_.block<3, 3>(3, 3); }
  Mat3 dp_dba() const { return bias_jacobian_.block<3, 3>(6, 0); }
  Mat3 dp_dbg() const { return bias_jacobian_.block<3, 3>(6, 3); }

  // First-order bias-corrected deltas at bias b (Forster eq. 44).
  Mat3 CorrectedRotation(const Vec6& bias) const;
  Vec3 CorrectedVelocity(const Vec6& bias) const;
  Vec3 CorrectedPosition(const Vec6& bias) const;

  // State j predicted from state i with bias b and world gravity g (e.g.
  // [0, 0, −9.81] for a z-up world): C_j = C_i ΔC(b), v_j = v_i + gΔt +
  // C_i Δv(b), p_j = p_i + v_iΔt + ½gΔt² + C_i Δp(b).
  NavState Predict(const NavState& start, const Vec6& bias, const Vec3& gravity) const;

 private:
  Vec6 bias_hat_;
  ImuNoise noise_;
  Mat3 C_bs_;
  double delta_t_ = 0.0;
  Mat3 delta_C_ = Mat3::Identity();
  Vec3 delta_v_ = Vec3::Zero();
  Vec3 delta_p_ = Vec3::Zero();
  Mat9 covariance_ = Mat9::Zero();
  Mat96 bias_jacobian_ = Mat96::Zero();
};

}  // namespace ctlio::imu
