// Dense linear algebra of marginalisation (SPEC §5), header-only and Eigen-only so that every
// estimator (the sliding window, the 1D smoothers, heterogeneous preintegration) uses the same
// code.
//
// A linearised Gaussian factor graph is summarised by its information matrix H = JᵀJ and vector
// b = Jᵀr (cost ½δᵀHδ + bᵀδ + const; the formulas below are linear in b, so the opposite sign
// convention H·x = η works identically). Marginalising the variables m onto the kept ones k is the
// Schur complement
//     H' = H_kk − H_km H_mm⁺ H_mk,   b' = b_k − H_km H_mm⁺ b_m.
//
// Singular blocks. H_mm is singular when a marginalised variable is not fully observed (a
// dangling velocity, a gauge freedom). Its unobserved directions carry no information to the kept
// variables, so the pseudo-inverse (not the inverse) is the right operator: it never produces NaN
// or Inf and gives the limit of a vanishing prior on those directions.
//
// Rank decisions. Information matrices mix units (rad, m, m/s, m/s²) and GP priors make their
// entries span 10+ orders of magnitude (SPEC §2: WNOJ Q⁻¹ entries 7.2e7 … 90 at Δt = 0.1), so a
// threshold relative to the largest eigenvalue of H itself would drop well-determined
// accelerations. We therefore decompose the Jacobi-scaled matrix S = D H D with D = diag(H)^(-1/2)
// (unit diagonal, eigenvalues in [0, n], invariant to the units of each coordinate) and drop the
// eigen-directions of S with eigenvalue ≤ relative_threshold · λ_max(S). The default 1e-12 is
// ~1e4× the eigen-solver's round-off (≈ n·ε·λ_max) and far below any genuine correlation of a
// well-posed problem (a 1e-12 scaled eigenvalue means a correlation coefficient of 1 − 5e-13).
// Coordinates with zero (or negative, i.e. invalid) diagonal carry no information and are dropped
// before scaling. Negative eigenvalues (round-off of a PSD matrix) are dropped the same way.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace ctlio {

inline constexpr double kDefaultRelativeEigenvalueThreshold = 1e-12;

// Result of decomposing a symmetric positive semi-definite matrix H (n×n):
//   H ≈ Dinv · V · diag(λ) · Vᵀ · Dinv,   Dinv = diag(√H_ii) (0 for dropped coordinates),
// keeping only the `rank` eigen-pairs (λ, V columns) above the threshold.
struct PsdDecomposition {
  Eigen::VectorXd inverse_scale;  // √H_ii, or 0 where the coordinate carries no information.
  Eigen::VectorXd scale;          // 1/√H_ii, or 0 where the coordinate carries no information.
  Eigen::VectorXd eigenvalues;    // rank kept eigenvalues of the scaled matrix (all > 0).
  Eigen::MatrixXd eigenvectors;   // n × rank.
  int rank = 0;
  int dropped = 0;  // informative coordinates minus rank: directions removed by the threshold.
};

inline PsdDecomposition DecomposePsd(
    const Eigen::MatrixXd& H, double relative_threshold = kDefaultRelativeEigenvalueThreshold) {
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

// Moore–Penrose-style pseudo-inverse of a PSD matrix on its well-determined subspace (in the
// Jacobi-scaled metric above): H⁺ = D V Λ⁻¹ Vᵀ D. Exact inverse when H is well conditioned.
inline Eigen::MatrixXd PseudoInverse(
    const Eigen::MatrixXd& H, double relative_threshold = kDefaultRelativeEigenvalueThreshold,
    int* rank = nullptr) {
  const PsdDecomposition d = DecomposePsd(H, relative_threshold);
  if (rank != nullptr) *rank = d.rank;
  const Eigen::MatrixXd DV = d.scale.asDiagonal() * d.eigenvectors;
  Eigen::MatrixXd Hinv = DV * d.eigenvalues.cwiseInverse().asDiagonal() * DV.transpose();
  return 0.5 * (Hinv + Hinv.transpose());
}

// Square-root form of the Gaussian ½δᵀHδ + bᵀδ: returns A (rank × n) and r0 (rank) such that
// ½‖A·δ + r0‖² equals it up to a constant, i.e. AᵀA = H and Aᵀr0 = b on the kept subspace:
//   A = √Λ Vᵀ D⁻¹,   r0 = Λ^(-1/2) Vᵀ D b.
// (b must lie in the range of H, which holds for any b = Jᵀr and its Schur complements; the part
// of b outside the kept subspace is dropped with it.) rank may be 0 (A is 0 × n).
inline int InformationSquareRoot(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                                 Eigen::MatrixXd* sqrt_information, Eigen::VectorXd* r0,
                                 double relative_threshold = kDefaultRelativeEigenvalueThreshold) {
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

struct SchurComplementResult {
  Eigen::MatrixXd information;  // H' (keep.size() × keep.size()), symmetric.
  Eigen::VectorXd vector;       // b'
  int marginalized_rank = 0;    // rank of H_mm used (< marginalize.size() ⇒ singular block).
};

// Schur complement of (H, b) onto the index set `keep`, marginalising the index set `marginalize`
// (indices into H; the two sets must be disjoint; indices in neither are ignored, i.e. treated as
// already marginalised out by the caller — pass every index to one of the sets if that is not what
// you want). The result is ordered as `keep`.
inline SchurComplementResult SchurComplement(
    const Eigen::MatrixXd& H, const Eigen::VectorXd& b, const std::vector<int>& keep,
    const std::vector<int>& marginalize,
    double relative_threshold = kDefaultRelativeEigenvalueThreshold) {
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

// Convenience for contiguous blocks: H ordered [m (first num_marginalized); k (the rest)].
inline SchurComplementResult SchurComplementLeading(
    const Eigen::MatrixXd& H, const Eigen::VectorXd& b, int num_marginalized,
    double relative_threshold = kDefaultRelativeEigenvalueThreshold) {
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
