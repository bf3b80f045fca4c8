#include "ctlio/factors/lidar/continuous_point_to_plane_batch.h"

#include <algorithm>
#include <vector>

#include "ctlio/factors/lidar/batch_square_root.h"

namespace ctlio {

// R and r₀ of the square-root form (header): RᵀR = H and Rᵀr₀ = g on H's informative subspace,
// from the lower triangle of H (overwritten). With s = diag(H)^(-1/2) (0 on a zero diagonal),
// S = s·H·s has a unit diagonal; its Cholesky factor with complete (diagonal) pivoting,
// S[p, p] = L·Lᵀ, is rank-revealing: each step takes the largest diagonal of the remaining Schur
// complement — what column p_k adds to the span of the columns before it — and the factorisation
// stops where that falls to `threshold` (the rest is rounding: no information). Then
// R(k, p_a) = L(a, k)/s(p_a) and L·r₀ = (s∘g)[p] on the kept rows. (Eigen's LDLT pivots on the
// original diagonal, all ones here, and divides by rounding-level pivots of a semidefinite S.)
// Returns false on a non-finite H or g.
bool BatchSquareRoot(Eigen::MatrixXd* H, const Eigen::VectorXd& g, double threshold,
                     Eigen::MatrixXd* R, Eigen::VectorXd* r0) {
  const Eigen::Index w = H->rows();
  if (!H->allFinite() || !g.allFinite()) return false;
  Eigen::VectorXd s(w), inverse_s(w);
  for (Eigen::Index i = 0; i < w; ++i) {
    const double d = (*H)(i, i);
    inverse_s[i] = d > 0.0 ? std::sqrt(d) : 0.0;
    s[i] = d > 0.0 ? 1.0 / inverse_s[i] : 0.0;
  }
  Eigen::MatrixXd& A = *H;  // S, then its Schur complements, in the lower triangle
  for (Eigen::Index j = 0; j < w; ++j) {
    for (Eigen::Index i = j; i < w; ++i) A(i, j) *= s[i] * s[j];
  }
  A.triangularView<Eigen::StrictlyUpper>() = A.transpose();  // full, for the symmetric swaps
  std::vector<Eigen::Index> p(static_cast<size_t>(w));
  for (Eigen::Index i = 0; i < w; ++i) p[static_cast<size_t>(i)] = i;
  Eigen::Index rank = 0;
  for (; rank < w; ++rank) {
    const Eigen::Index k = rank;
    Eigen::Index pivot;
    const double largest = A.diagonal().tail(w - k).maxCoeff(&pivot);
    if (!(largest > threshold)) break;
    pivot += k;
    if (pivot != k) {
      A.row(k).swap(A.row(pivot));
      A.col(k).swap(A.col(pivot));
      std::swap(p[static_cast<size_t>(k)], p[static_cast<size_t>(pivot)]);
    }
    const double root = std::sqrt(A(k, k));
    A(k, k) = root;
    A.col(k).tail(w - k - 1) /= root;
    // The Schur complement of the trailing block, both triangles (the swaps read rows and columns).
    A.bottomRightCorner(w - k - 1, w - k - 1).noalias() -=
        A.col(k).tail(w - k - 1) * A.col(k).tail(w - k - 1).transpose();
  }
  // L = the first `rank` columns of A's lower triangle (rows in pivot order).
  Eigen::VectorXd y(rank);
  for (Eigen::Index a = 0; a < rank; ++a) {
    double sum = s[p[static_cast<size_t>(a)]] * g[p[static_cast<size_t>(a)]];
    for (Eigen::Index k = 0; k < a; ++k) sum -= A(a, k) * y[k];
    y[a] = sum / A(a, a);
  }
  R->setZero(w, w);
  r0->setZero(w);
  r0->head(rank) = y;
  for (Eigen::Index a = 0; a < w; ++a) {
    const Eigen::Index column = p[static_cast<size_t>(a)];
    for (Eigen::Index k = 0; k < std::min(a + 1, rank); ++k) {
      (*R)(k, column) = A(a, k) * inverse_s[column];
    }
  }
  return true;
}

bool ContinuousPointToPlaneBatch::EvaluateSquareRoot(double const* const* parameters,
                                                     double* residuals, double** jacobians) const {
  const size_t n = points_.size();
  const int w = tangent_size();
  bool want = false;
  if (jacobians != nullptr) {
    for (int b = 0; b < blocks_; ++b) want = want || jacobians[b] != nullptr;
  }
  const bool extrinsic = blocks_ == 7;
  const SE3 T_rl = extrinsic ? PoseManifold::Pose(parameters[6]) : SE3();
  const size_t chunks = work_items();
  // Per chunk: ‖r‖² of its rows plus their Σ ρ − ρ'·e² (twice their robust cost) and, with
  // Jacobians, the lower triangle of JᵀJ and Jᵀr.
  std::vector<double> chunk_cost(chunks, 0.0);
  std::vector<Eigen::MatrixXd> chunk_H(want ? chunks : 0);
  std::vector<Eigen::VectorXd> chunk_g(want ? chunks : 0);
  std::atomic<bool> concave{true};
  const auto evaluate_chunks = [&](size_t begin, size_t end) {
    // Row-major: its transpose is column-major, the layout rankUpdate packs fastest.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(
        want ? static_cast<Eigen::Index>(kChunkRows) : 0, w);
    Eigen::VectorXd r(static_cast<Eigen::Index>(kChunkRows));
    Eigen::Matrix<double, 1, 18> J_k, J_k1;
    Eigen::Matrix<double, 1, 6> J_tau;
    PlaneAssociation m;
    for (size_t c = begin; c < end; ++c) {
      const size_t first = c * kChunkRows, last = std::min(n, first + kChunkRows);
      const auto rows = static_cast<Eigen::Index>(last - first);
      double gaps = 0.0;  // Σ ρ(e²) − ρ'(e²)·e², in row order
      for (size_t i = first; i < last; ++i) {
        const Point& p = points_[i];
        const PlaneAssociation* association = &p.association;
        if (extrinsic) {  // as the point rows (header)
          m = p.association;
          m.point_robot = T_rl * p.point_lidar;
          association = &m;
        }
        const double e = ContinuousPointToPlane::EvaluateTangent(
            *p.pose, *association, parameters, want ? &J_k : nullptr, want ? &J_k1 : nullptr,
            want && extrinsic ? &J_tau : nullptr);
        double scale = 1.0;
        if (loss_ != nullptr) {
          double rho[3];
          loss_->Evaluate(e * e, rho);
          if (rho[2] > 0.0) {
            concave.store(false, std::memory_order_relaxed);
            return;
          }
          scale = std::sqrt(rho[1]);
          gaps += rho[0] - rho[1] * e * e;
        }
        const auto row = static_cast<Eigen::Index>(i - first);
        r[row] = scale * e;
        if (!want) continue;
        J.row(row).segment<18>(0) = scale * J_k;
        J.row(row).segment<18>(18) = scale * J_k1;
        if (extrinsic) J.row(row).segment<6>(36) = -scale * J_tau;  // de/dδ_rl = −de/dδT(τ)
      }
      chunk_cost[c] = r.head(rows).squaredNorm() + gaps;
      if (!want) continue;
      chunk_H[c].setZero(w, w);
      chunk_H[c].selfadjointView<Eigen::Lower>().rankUpdate(J.topRows(rows).transpose());
      chunk_g[c].noalias() = J.topRows(rows).transpose() * r.head(rows);
    }
  };
  if (row_runner_) {
    row_runner_(chunks, evaluate_chunks);
  } else {
    evaluate_chunks(0, chunks);
  }
  if (!concave.load(std::memory_order_relaxed)) return false;
  double cost = 0.0;  // ‖r‖² of the point rows and the constant row's square, in chunk order
  for (const double c : chunk_cost) cost += c;
  if (!want) {
    std::fill_n(residuals, w, 0.0);
    residuals[w] = std::sqrt(cost);
    return true;
  }
  Eigen::MatrixXd H = std::move(chunk_H[0]);
  Eigen::VectorXd g = std::move(chunk_g[0]);
  for (size_t c = 1; c < chunks; ++c) {
    H += chunk_H[c];  // lower triangles (the upper ones are zero)
    g += chunk_g[c];
  }
  Eigen::MatrixXd R;
  Eigen::VectorXd r0;
  if (!BatchSquareRoot(&H, g, kPivotThreshold, &R, &r0)) return false;
  std::copy_n(r0.data(), w, residuals);
  residuals[w] = std::sqrt(std::max(cost - r0.squaredNorm(), 0.0));  // clamps rounding only
  for (int b = 0; b < blocks_; ++b) {
    if (jacobians[b] == nullptr) continue;
    const bool pose = b == 0 || b == 3 || b == 6;
    for (int j = 0; j < w; ++j) {
      const Eigen::Matrix<double, 1, 6> row = R.row(j).segment<6>(6 * b);
      double* out = jacobians[b] + j * kBlockSizes[b];
      if (pose) {
        LiftPoseJacobian<1>(row, parameters[b], out);
      } else {
        std::copy_n(row.data(), 6, out);
      }
    }
    std::fill_n(jacobians[b] + w * kBlockSizes[b], kBlockSizes[b], 0.0);
  }
  return true;
}

}  // namespace ctlio
