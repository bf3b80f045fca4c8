// IMU as an input in 1D (the paper's baseline, SPEC §3 and §6): the state [p, v] is driven by the
// accelerometer, ṗ = v, v̇ = u + w, where u is held constant between samples (zero-order hold) and
// w is the input noise with one variance Q_k per sample interval. Between two estimator states
// (the position-measurement times) the inputs are preintegrated — the 1D, bias-free form of
// Forster et al.'s on-manifold preintegration — into
//   x_b = A(T)·x_a + [Δp; Δv] + n,  n ~ N(0, Σ),  A(T) = [[1, T], [0, 1]],
// with Σ propagated piece by piece: Σ ← A(δ)ΣA(δ)ᵀ + q·B(δ)B(δ)ᵀ, B(δ) = [δ²/2; δ].
// One piece gives a rank-one Σ, so a factor needs at least two pieces (checked).
// Calibration (derived in docs/experiments/study-1d.md, SPEC §6): the held sample's error over a
// stretch makes the exact velocity noise (σ_acc² + Qc·Δt/3)·Δt² on WNOJ data, so the one-parameter
// model q·BBᵀ is exact in v for q = σ_acc² + Qc·Δt/3 (its p entries are off by O(Qc·Δt⁵),
// negligible); on Singer data the hold errors are correlated and their long-run variance gives q ≈
// σ_acc² + Qc·Δt/12.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Dense>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::study {

// One zero-order-hold stretch of the input: duration δ, input u, input noise variance q
// (the discrete per-sample variance Q_k of the paper).
struct InputPiece {
  double duration;
  double input;
  double variance;
};

class ImuInputPreintegration {
 public:
  ImuInputPreintegration() = default;
  void Integrate(const InputPiece& piece);
  double dt() const { return dt_; }
  double delta_p() const { return delta_p_; }
  double delta_v() const { return delta_v_; }
  const Eigen::Matrix2d& covariance() const { return covariance_; }

 private:
  double dt_ = 0.0;
  double delta_p_ = 0.0;
  double delta_v_ = 0.0;
  Eigen::Matrix2d covariance_ = Eigen::Matrix2d::Zero();
};

// Residual e = L⁻¹([p_b − p_a − v_a·T − Δp; v_b − v_a − Δv]) with L Lᵀ = Σ; blocks [p, v]_a,
// [p, v]_b. Linear, so the Jacobians are constant: L⁻¹·[−A(T), I].
class ImuInputFactor final : public ceres::SizedCostFunction<2, 2, 2> {
 public:
  explicit ImuInputFactor(const ImuInputPreintegration& preintegration);
  bool Evaluate(double const* const* x, double* residual, double** jacobians) const override;

 private:
  ImuInputPreintegration pre_;
  Eigen::Matrix2d whiten_;  // L⁻¹
};

}  // namespace ctlio::study
