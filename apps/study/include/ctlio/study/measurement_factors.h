// Unary factors of the 1D study: a scalar measurement of one state component (position or
// acceleration) and the Gaussian prior on the first state. State per time: [p, v] (IMU as input)
// or [p, v, a] (IMU as measurement), SPEC §6.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Dense>
#include <stdexcept>
#include <string>

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio::study {

// z = x[index] + n, n ~ N(0, σ²): whitened residual e = (x[index] − z)/σ.
template <int D>
class ScalarMeasurement final : public ceres::SizedCostFunction<1, D> {
 public:
  ScalarMeasurement(int index, double z, double sigma) : index_(index), z_(z), sigma_(sigma) {
    if (index < 0 || index >= D || !(sigma > 0.0)) {
      throw std::invalid_argument(std::string(__FILE__) + ": ScalarMeasurement: bad index/sigma");
    }
  }
  bool Evaluate(double const* const* x, double* residual, double** jacobians) const override {
    residual[0] = (x[0][index_] - z_) / sigma_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int i = 0; i < D; ++i) jacobians[0][i] = 0.0;
      jacobians[0][index_] = 1.0 / sigma_;
    }
    return true;
  }

 private:
  int index_;
  double z_;
  double sigma_;
};

// x_0 ~ N(mean, P0): e = W(x − mean) with WᵀW = P0⁻¹, so ‖e‖² = (x − mean)ᵀP0⁻¹(x − mean).
template <int D>
class InitialStatePrior final : public ceres::SizedCostFunction<D, D> {
 public:
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  InitialStatePrior(const Vector& mean, const Matrix& covariance)
      : mean_(mean),
        sqrt_information_(SqrtInformationFromCovariance<D>(covariance, "InitialStatePrior")) {}
  bool Evaluate(double const* const* x, double* residual, double** jacobians) const override {
    Eigen::Map<Vector> r(residual);
    r = sqrt_information_ * (Eigen::Map<const Vector>(x[0]) - mean_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, D, D, Eigen::RowMajor>> J(jacobians[0]);
      J = sqrt_information_;
    }
    return true;
  }

 private:
  Vector mean_;
  Matrix sqrt_information_;
};

}  // namespace ctlio::study
