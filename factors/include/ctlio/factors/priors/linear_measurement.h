// A linear Gaussian measurement of a vector block: z = H·x + n, n ~ N(0, R):
//   r = W·(H·x − z),  WᵀW = R⁻¹,  ∂r/∂x = W·H.
// E.g. the position of a stacked vector-GP knot x = [p; v; a] (H = [I 0 0]): positions-only
// estimation with a GP prior (VectorGpPrior). Parameter block: x (N).
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio {

template <int M, int N>
class LinearMeasurement final : public ceres::SizedCostFunction<M, N> {
 public:
  using Measurement = Eigen::Matrix<double, M, 1>;
  using Matrix = Eigen::Matrix<double, M, N>;

  LinearMeasurement(const Measurement& z, const Matrix& H,
                    const Eigen::Matrix<double, M, M>& covariance)
      : sqrt_info_(SqrtInformationFromCovariance<M>(covariance, "LinearMeasurement")),
        W_H_(sqrt_info_ * H),
        W_z_(sqrt_info_ * z) {}

  // The first M entries of x measured (H = [I 0]).
  static LinearMeasurement* Leading(const Measurement& z,
                                    const Eigen::Matrix<double, M, M>& covariance) {
    Matrix H = Matrix::Zero();
    H.template leftCols<M>().setIdentity();
    return new LinearMeasurement(z, H, covariance);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Matrix<double, N, 1>> x(parameters[0]);
    Eigen::Map<Measurement> r(residuals);
    r.noalias() = W_H_ * x;
    r -= W_z_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      constexpr int kOrder = N == 1 ? Eigen::ColMajor : Eigen::RowMajor;
      Eigen::Map<Eigen::Matrix<double, M, N, kOrder>>(jacobians[0], M, N) = W_H_;
    }
    return true;
  }

 private:
  Eigen::Matrix<double, M, M> sqrt_info_;
  Matrix W_H_;       // W·H
  Measurement W_z_;  // W·z
};

}  // namespace ctlio
