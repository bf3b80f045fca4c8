// W with WᵀW = Σ⁻¹ from a covariance Σ (W = L⁻¹ for Σ = LLᵀ): the whitening matrix every
// unary prior takes. Throws (file:line) when Σ is not symmetric positive definite.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <sstream>
#include <stdexcept>

namespace ctlio {

template <int N>
Eigen::Matrix<double, N, N> SqrtInformationFromCovariance(
    const Eigen::Matrix<double, N, N>& covariance) {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.isApprox(covariance.transpose()) ||
      !covariance.allFinite()) {
    std::ostringstream os;
    os << __FILE__ << ":" << __LINE__ << ": covariance is not symmetric positive definite";
    throw std::runtime_error(os.str());
  }
  return llt.matrixL().solve(Eigen::Matrix<double, N, N>::Identity());
}

}  // namespace ctlio
