// Dense linear algebra of marginalisation (SPEC §5), Eigen-only so that every estimator (the
// sliding window, the 1D smoothers, heterogeneous preintegration) uses the same code. The
// definitions are in solvers/src/schur_complement.cc: inline here, the dense eigen-solver cost
// ~2 s of compile time in each of the ~160 files that include this header.
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

#include <Eigen/Core>
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

PsdDecomposition DecomposePsd(const Eigen::MatrixXd& H,
                              double relative_threshold = kDefaultRelativeEigenvalueThreshold);

// Moore–Penrose-style pseudo-inverse of a PSD matrix on its well-determined subspace (in the
// Jacobi-scaled metric above): H⁺ = D V Λ⁻¹ Vᵀ D. Exact inverse when H is well conditioned.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& H,
                              double relative_threshold = kDefaultRelativeEigenvalueThreshold,
                              int* rank = nullptr);

// Square-root form of the Gaussian ½δᵀHδ + bᵀδ: returns A (rank × n) and r0 (rank) such that
// ½‖A·δ + r0‖² equals it up to a constant, i.e. AᵀA = H and Aᵀr0 = b on the kept subspace:
//   A = √Λ Vᵀ D⁻¹,   r0 = Λ^(-1/2) Vᵀ D b.
// (b must lie in the range of H, which holds for any b = Jᵀr and its Schur complements; the part
// of b outside the kept subspace is dropped with it.) rank may be 0 (A is 0 × n).
int InformationSquareRoot(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                          Eigen::MatrixXd* sqrt_information, Eigen::VectorXd* r0,
                          double relative_threshold = kDefaultRelativeEigenvalueThreshold);

struct SchurComplementResult {
  Eigen::MatrixXd information;  // H' (keep.size() × keep.size()), symmetric.
  Eigen::VectorXd vector;       // b'
  int marginalized_rank = 0;    // rank of H_mm used (< marginalize.size() ⇒ singular block).
};

// Schur complement of (H, b) onto the index set `keep`, marginalising the index set `marginalize`
// (indices into H; the two sets must be disjoint; indices in neither are ignored, i.e. treated as
// already marginalised out by the caller — pass every index to one of the sets if that is not what
// you want). The result is ordered as `keep`.
SchurComplementResult SchurComplement(
    const Eigen::MatrixXd& H, const Eigen::VectorXd& b, const std::vector<int>& keep,
    const std::vector<int>& marginalize,
    double relative_threshold = kDefaultRelativeEigenvalueThreshold);

// Convenience for contiguous blocks: H ordered [m (first num_marginalized); k (the rest)].
SchurComplementResult SchurComplementLeading(
    const Eigen::MatrixXd& H, const Eigen::VectorXd& b, int num_marginalized,
    double relative_threshold = kDefaultRelativeEigenvalueThreshold);

}  // namespace ctlio
