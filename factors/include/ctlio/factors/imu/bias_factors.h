// IMU bias factors (SPEC §3). Bias blocks are plain 6-vectors b = [b_a; b_g].
//
// BiasRandomWalk between two knots at times t_k < t_{k+1}: ḃ = w, w ~ GP(0,
// Q_c δ(t − t')), so b_{k+1} − b_k ~ N(0, Q_c·Δt). The covariance is scaled by
// Δt: the model does not depend on the knot rate (the reference code uses a
// fixed covariance per knot, SPEC §3). Q_c = diag(q_a I₃, q_g I₃) with q the
// squared random-walk densities (EuRoC: (3.0e-3)² m²/s⁵ and (1.9393e-5)²
// rad²/s³). Residual e = (Q_cΔt)^{-1/2}(b_{k+1} − b_k).
//
// BiasPrior: e = Σ^{-1/2}(b − b̄) for an initial bias b̄ with covariance Σ.
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

class BiasRandomWalk final : public ceres::SizedCostFunction<6, 6, 6> {
 public:
  // accel_psd, gyro_psd: q_a, q_g (variance per second), dt = t_{k+1} − t_k > 0.
  // Throws std::invalid_argument on non-positive arguments.
  BiasRandomWalk(double accel_psd, double gyro_psd, double dt);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  const Vec6& sqrt_information_diagonal() const { return sqrt_info_; }

 private:
  Vec6 sqrt_info_;
};

class BiasPrior final : public ceres::SizedCostFunction<6, 6> {
 public:
  // Throws std::invalid_argument if covariance is not positive definite.
  BiasPrior(const Vec6& mean, const Mat6& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Vec6 mean_;
  Mat6 sqrt_information_;
};

}  // namespace ctlio::imu
