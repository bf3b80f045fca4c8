// Unary prior on a Euclidean block: r = W·(x − x̄), WᵀW = Σ⁻¹. The knot velocity ϖ and
// acceleration ϖ̇ (SPEC §1) are plain 6-vectors, so VelocityPrior and AccelerationPrior are
// this factor with N = 6 (also usable for biases: N = 6, or any other vector block).
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio {

template <int N>
class EuclideanPrior final : public ceres::SizedCostFunction<N, N> {
 public:
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;

  EuclideanPrior(const Vector& mean, const Matrix& sqrt_information)
      : mean_(mean), sqrt_info_(sqrt_information) {}
  static EuclideanPrior* FromCovariance(const Vector& mean, const Matrix& covariance) {
    return new EuclideanPrior(mean, SqrtInformationFromCovariance<N>(covariance));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Vector> x(parameters[0]);
    Eigen::Map<Vector> r(residuals);
    r.noalias() = sqrt_info_ * (x - mean_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>> J(jacobians[0], N, N);
      J = sqrt_info_;
    }
    return true;
  }

 private:
  Vector mean_;
  Matrix sqrt_info_;
};

using VelocityPrior = EuclideanPrior<6>;
using AccelerationPrior = EuclideanPrior<6>;

}  // namespace ctlio
