// W with WᵀW = Σ⁻¹ from a covariance Σ (W = L⁻¹ for Σ = LLᵀ): the one whitening of a Gaussian
// residual, r = W·e has identity covariance. Every factor that takes a covariance whitens with it.
// Throws std::invalid_argument (file:line, and `what` naming the caller) when Σ is not finite,
// symmetric and positive definite.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <sstream>
#include <stdexcept>

namespace ctlio {

template <int N>
Eigen::Matrix<double, N, N> SqrtInformationFromCovariance(
    const Eigen::Matrix<double, N, N>& covariance, const char* what = "covariance") {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.isApprox(covariance.transpose()) ||
      !covariance.allFinite()) {
    std::ostringstream os;
    os << __FILE__ << ":" << __LINE__ << ": " << what
       << " is not a finite symmetric positive definite matrix";
    throw std::invalid_argument(os.str());
  }
  return llt.matrixL().solve(Eigen::Matrix<double, N, N>::Identity());
}

}  // namespace ctlio
