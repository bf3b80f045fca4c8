// Definitions of solvers/schur_complement.h (the rank decisions and their threshold are explained
// there).
#include "ctlio/solvers/schur_complement.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio {

PsdDecomposition DecomposePsd(const Eigen::MatrixXd& H, double relative_threshold) {
  const Eigen::Index n = H.rows();
  if (H.cols() != n) {
    std::ostringstream msg;
    msg << __FILE__ << ":" << __LINE__ << ": DecomposePsd needs a square matrix, got " << H.rows()
        << "x" << H.cols();
    throw std::invalid_argument(msg.str());
  }
  if (!H.allFinite()) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": DecomposePsd: information matrix has NaN/Inf entries");
  }
  PsdDecomposition d;
  d.inverse_scale = Eigen::VectorXd::Zero(n);
  d.scale = Eigen::VectorXd::Zero(n);
  int informative = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (H(i, i) > 0.0) {
      d.inverse_scale[i] = std::sqrt(H(i, i));
      d.scale[i] = 1.0 / d.inverse_scale[i];
      ++informative;
    }
  }
  if (n == 0 || informative == 0) {
    d.eigenvectors.resize(n, 0);
    d.eigenvalues.resize(0);
    return d;
  }
  // Symmetrise: callers accumulate H from products that are symmetric only up to round-off.
  Eigen::MatrixXd S = d.scale.asDiagonal() * (0.5 * (H + H.transpose())) * d.scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
  const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
  const double lambda_max = std::max(lambda[n - 1], 0.0);
  const double cutoff = relative_threshold * lambda_max;
  Eigen::Index first = n;
  while (first > 0 && lambda[first - 1] > cutoff && lambda[first - 1] > 0.0) --first;
  d.rank = static_cast<int>(n - first);
  d.dropped = informative - d.rank;
  d.eigenvalues = lambda.tail(d.rank);
  d.eigenvectors = eig.eigenvectors().rightCols(d.rank);
  return d;
}

Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& H, double relative_threshold, int* rank) {
  const PsdDecomposition d = DecomposePsd(H, relative_threshold);
  if (rank != nullptr) *rank = d.rank;
  const Eigen::MatrixXd DV = d.scale.asDiagonal() * d.eigenvectors;
  Eigen::MatrixXd Hinv = DV * d.eigenvalues.cwiseInverse().asDiagonal() * DV.transpose();
  return 0.5 * (Hinv + Hinv.transpose());
}

int InformationSquareRoot(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                          Eigen::MatrixXd* sqrt_information, Eigen::VectorXd* r0,
                          double relative_threshold) {
  if (b.size() != H.rows()) {
    std::ostringstream msg;
    msg << __FILE__ << ":" << __LINE__ << ": InformationSquareRoot: b has " << b.size()
        << " entries, H is " << H.rows() << "x" << H.cols();
    throw std::invalid_argument(msg.str());
  }
  if (!b.allFinite()) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": InformationSquareRoot: b has NaN/Inf entries");
  }
  const PsdDecomposition d = DecomposePsd(H, relative_threshold);
  const Eigen::VectorXd sqrt_lambda = d.eigenvalues.cwiseSqrt();
  *sqrt_information =
      sqrt_lambda.asDiagonal() * d.eigenvectors.transpose() * d.inverse_scale.asDiagonal();
  *r0 = sqrt_lambda.cwiseInverse().asDiagonal() * d.eigenvectors.transpose() *
        d.scale.asDiagonal() * b;
  return d.rank;
}

SchurComplementResult SchurComplement(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                                      const std::vector<int>& keep,
                                      const std::vector<int>& marginalize,
                                      double relative_threshold) {
  const int n = static_cast<int>(H.rows());
  if (H.cols() != n || b.size() != n) {
    std::ostringstream msg;
    msg << __FILE__ << ":" << __LINE__ << ": SchurComplement: H is " << H.rows() << "x" << H.cols()
        << ", b has " << b.size() << " entries";
    throw std::invalid_argument(msg.str());
  }
  if (!H.allFinite() || !b.allFinite()) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": SchurComplement: H or b has NaN/Inf entries");
  }
  std::vector<char> used(n, 0);
  for (const std::vector<int>* set : {&keep, &marginalize}) {
    for (int i : *set) {
      if (i < 0 || i >= n || used[i]) {
        std::ostringstream msg;
        msg << __FILE__ << ":" << __LINE__ << ": SchurComplement: index " << i
            << (i < 0 || i >= n ? " out of range [0, " + std::to_string(n) + ")"
                                : std::string(" listed twice"));
        throw std::invalid_argument(msg.str());
      }
      used[i] = 1;
    }
  }
  const int nk = static_cast<int>(keep.size());
  const int nm = static_cast<int>(marginalize.size());
  Eigen::MatrixXd Hkk(nk, nk), Hkm(nk, nm), Hmm(nm, nm);
  Eigen::VectorXd bk(nk), bm(nm);
  for (int i = 0; i < nk; ++i) {
    bk[i] = b[keep[i]];
    for (int j = 0; j < nk; ++j) Hkk(i, j) = H(keep[i], keep[j]);
    for (int j = 0; j < nm; ++j) Hkm(i, j) = H(keep[i], marginalize[j]);
  }
  for (int i = 0; i < nm; ++i) {
    bm[i] = b[marginalize[i]];
    for (int j = 0; j < nm; ++j) Hmm(i, j) = H(marginalize[i], marginalize[j]);
  }
  SchurComplementResult result;
  const Eigen::MatrixXd Hmm_inv = PseudoInverse(Hmm, relative_threshold, &result.marginalized_rank);
  const Eigen::MatrixXd K = Hkm * Hmm_inv;  // nk × nm
  result.information = Hkk - K * Hkm.transpose();
  result.information = 0.5 * (result.information + result.information.transpose()).eval();
  result.vector = bk - K * bm;
  return result;
}

SchurComplementResult SchurComplementLeading(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                                             int num_marginalized, double relative_threshold) {
  const int n = static_cast<int>(H.rows());
  if (num_marginalized < 0 || num_marginalized > n) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": SchurComplementLeading: num_marginalized out of range");
  }
  std::vector<int> m(num_marginalized), k(n - num_marginalized);
  for (int i = 0; i < num_marginalized; ++i) m[i] = i;
  for (int i = num_marginalized; i < n; ++i) k[i - num_marginalized] = i;
  return SchurComplement(H, b, k, m, relative_threshold);
}

}  // namespace ctlio
