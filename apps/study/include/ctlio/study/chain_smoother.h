// Exact full-trajectory smoother for a chain of states, with marginal posterior covariances.
//
// Every estimator of the 1D study is a chain: a state per time, factors on one state
// (measurements) or on two consecutive states (motion priors, IMU-as-input factors,
// heterogeneous-preintegration factors). The whitened Jacobian is block bidiagonal, so the
// Gauss-Newton step and the marginal covariances cost O(N·D³).
//
// Why square-root form. At 400 Hz the GP prior's information Q(Δt)⁻¹ reaches 1e16 (SPEC §2:
// WNOJ Q11 = Δt⁵/20), while the posterior position variance is ~1e-5: the normal equations
// JᵀJ have a condition number ~1e21, and a block Cholesky of them (or ceres' normal-equation
// solvers) loses every digit — we measured 8 cm position errors from round-off alone. So the
// chain is eliminated by Householder QR on the whitened Jacobian rows (a square-root information
// smoother): the condition number that matters is that of J, the square root of JᵀJ's.
//   Forward: for i = 0..N−2, QR of [[R̃_i, 0, ρ̃_i], [unary rows of i], [A_i, B_i, r_i]] gives
//   [[R_ii, R_i,i+1, ρ_i], [0, R̃_{i+1}, ρ̃_{i+1}]]; the last state's R_NN from its rows.
//   Back substitution: δ_N = −R_NN⁻¹ρ_N, δ_i = −R_ii⁻¹(ρ_i + R_i,i+1 δ_{i+1}).
//   Covariances: Σ_N = R_NN⁻¹R_NN⁻ᵀ, Σ_i = R_ii⁻¹R_ii⁻ᵀ + G_i Σ_{i+1} G_iᵀ with
//   G_i = R_ii⁻¹R_i,i+1, and Σ_i,i+1 = −G_i Σ_{i+1} (a sum of PSD terms: no cancellation).
// The same numbers as ceres::Solve (DENSE_QR) + ceres::Covariance, checked in
// test/study/chain_smoother_test.cc.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Dense>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::study {

template <int D>
class ChainSmoother {
 public:
  using Block = Eigen::Matrix<double, D, D>;
  using Vector = Eigen::Matrix<double, D, 1>;
  static constexpr int kMaxResiduals = 9;
  // Rows of one factor: [J_first (D) | J_second (D) | residual]; unary factors leave J_second 0.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 2 * D + 1>;

  explicit ChainSmoother(int num_states)
      : unary_(num_states), pair_(num_states > 0 ? num_states - 1 : 0) {
    if (num_states <= 0) throw std::invalid_argument(Where() + "need at least one state");
  }

  int size() const { return static_cast<int>(unary_.size()); }

  // Linearises a Ceres cost function on state `first` (one block of size D) or on states
  // (first, first + 1) at the given estimates and stores its whitened Jacobian rows.
  void AddFactor(const ceres::CostFunction& cost, int first, const std::vector<Vector>& x) {
    const int num_blocks = static_cast<int>(cost.parameter_block_sizes().size());
    const int m = cost.num_residuals();
    if (num_blocks < 1 || num_blocks > 2 || m > kMaxResiduals || first < 0 ||
        first + num_blocks > size()) {
      throw std::invalid_argument(Where() + "factor does not fit the chain");
    }
    for (int b = 0; b < num_blocks; ++b) {
      if (cost.parameter_block_sizes()[b] != D) {
        throw std::invalid_argument(Where() + "parameter block size differs from D");
      }
    }
    std::array<double, kMaxResiduals> residual;
    std::array<double, kMaxResiduals * D> jac0, jac1;
    const double* params[2] = {x.at(first).data(),
                               num_blocks == 2 ? x.at(first + 1).data() : nullptr};
    double* jacobians[2] = {jac0.data(), jac1.data()};
    if (!cost.Evaluate(params, residual.data(), jacobians)) {
      throw std::runtime_error(Where() + "cost function evaluation failed");
    }
    Rows& rows = num_blocks == 1 ? unary_[first] : pair_[first];
    const Eigen::Index r0 = rows.rows();
    rows.conservativeResize(r0 + m, Eigen::NoChange);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < D; ++j) {
        rows(r0 + i, j) = jac0[i * D + j];
        rows(r0 + i, D + j) = num_blocks == 2 ? jac1[i * D + j] : 0.0;
      }
      rows(r0 + i, 2 * D) = residual[i];
    }
  }

  // Adds a Gaussian factor on (first, first + 1) given as whitened rows [J_first | J_second | r]
  // (e.g. a heterogeneous-preintegration factor in square-root form).
  void AddPairRows(int first, const Rows& rows) {
    if (first < 0 || first + 1 >= size()) throw std::invalid_argument(Where() + "bad pair");
    Rows& dst = pair_[first];
    const Eigen::Index r0 = dst.rows();
    dst.conservativeResize(r0 + rows.rows(), Eigen::NoChange);
    dst.bottomRows(rows.rows()) = rows;
  }

  // Heterogeneous preintegration in square-root form (paper eq. 26, SPEC §3): eliminates every
  // state strictly between the first and the last one and returns one joint Gaussian factor
  // on (first, last) as whitened rows [J_first | J_last | r] (2D rows). It is the Schur complement
  // of the chain onto its two ends, computed by sequential Householder QR (s_j eliminated from
  // [[carry on (first, s_j)], [unary rows of s_j], [pair rows (s_j, s_{j+1})]]), which keeps full
  // precision where the information-form Schur complement loses it (see the file comment).
  Rows EliminateInterior() const {
    const int n = size();
    if (n < 2) throw std::invalid_argument(Where() + "need two end states");
    // Carry over columns [first | s_j | r], starting with s_j = s_1.
    Rows carry(unary_[0].rows() + pair_[0].rows(), 2 * D + 1);
    carry << unary_[0], pair_[0];
    using Work = Eigen::Matrix<double, Eigen::Dynamic, 3 * D + 1>;
    Work M;
    for (int j = 1; j < n - 1; ++j) {
      // Columns [s_j | first | s_{j+1} | r]: s_j is eliminated first.
      const Eigen::Index rows = carry.rows() + unary_[j].rows() + pair_[j].rows();
      M.setZero(std::max<Eigen::Index>(rows, 3 * D + 1), 3 * D + 1);
      Eigen::Index r = 0;
      M.block(r, 0, carry.rows(), D) = carry.middleCols(D, D);
      M.block(r, D, carry.rows(), D) = carry.leftCols(D);
      M.block(r, 3 * D, carry.rows(), 1) = carry.col(2 * D);
      r += carry.rows();
      M.block(r, 0, unary_[j].rows(), D) = unary_[j].leftCols(D);
      M.block(r, 3 * D, unary_[j].rows(), 1) = unary_[j].col(2 * D);
      r += unary_[j].rows();
      M.block(r, 0, pair_[j].rows(), D) = pair_[j].leftCols(D);
      M.block(r, 2 * D, pair_[j].rows(), D) = pair_[j].middleCols(D, D);
      M.block(r, 3 * D, pair_[j].rows(), 1) = pair_[j].col(2 * D);
      Eigen::HouseholderQR<Work> qr(M);
      const Work& R = qr.matrixQR();
      carry.resize(2 * D, 2 * D + 1);
      carry = R.block(D, D, 2 * D, 2 * D + 1).template triangularView<Eigen::Upper>();
    }
    if (unary_[n - 1].rows() > 0) {
      Rows last = Rows::Zero(unary_[n - 1].rows(), 2 * D + 1);
      last.middleCols(D, D) = unary_[n - 1].leftCols(D);
      last.col(2 * D) = unary_[n - 1].col(2 * D);
      Rows joined(carry.rows() + last.rows(), 2 * D + 1);
      joined << carry, last;
      carry = joined;
    }
    return carry;
  }

  // Gauss-Newton correction δ (minimiser of Σ‖Jδ + r‖²) and marginal covariances; any output may
  // be null. Throws if a state is not determined (singular R_ii).
  void Solve(std::vector<Vector>* delta, std::vector<Block>* covariance,
             std::vector<Block>* cross_covariance = nullptr) const {
    const int n = size();
    std::vector<Block> Rii(n), Rij(n);
    std::vector<Vector> rho(n);
    // Carried square-root prior on the current state: [R̃ | ρ̃] (D rows).
    Eigen::Matrix<double, D, D + 1> carry = Eigen::Matrix<double, D, D + 1>::Zero();
    using Work = Eigen::Matrix<double, Eigen::Dynamic, 2 * D + 1>;
    Work M;
    for (int i = 0; i < n; ++i) {
      const bool last = i + 1 == n;
      const Eigen::Index rows = D + unary_[i].rows() + (last ? 0 : pair_[i].rows());
      // At least 2D + 1 rows so that the QR's upper triangle holds both diagonal blocks.
      M.setZero(std::max<Eigen::Index>(rows, 2 * D + 1), 2 * D + 1);
      M.template block<D, D>(0, 0) = carry.template leftCols<D>();
      M.template block<D, 1>(0, 2 * D) = carry.col(D);
      Eigen::Index r = D;
      if (unary_[i].rows() > 0) {
        M.middleRows(r, unary_[i].rows()) = unary_[i];
        r += unary_[i].rows();
      }
      if (!last && pair_[i].rows() > 0) M.middleRows(r, pair_[i].rows()) = pair_[i];
      if (last) {
        // Only the first D columns and the residual matter.
        Eigen::Matrix<double, Eigen::Dynamic, D + 1> L(M.rows(), D + 1);
        L.template leftCols<D>() = M.template leftCols<D>();
        L.col(D) = M.col(2 * D);
        Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, D + 1>> qr(L);
        const auto& R = qr.matrixQR();
        Rii[i] = R.template topLeftCorner<D, D>().template triangularView<Eigen::Upper>();
        rho[i] = R.template block<D, 1>(0, D);
      } else {
        Eigen::HouseholderQR<Work> qr(M);
        const Work& R = qr.matrixQR();
        Rii[i] = R.template topLeftCorner<D, D>().template triangularView<Eigen::Upper>();
        Rij[i] = R.template block<D, D>(0, D);
        rho[i] = R.template block<D, 1>(0, 2 * D);
        carry.setZero();
        carry.template leftCols<D>() =
            R.template block<D, D>(D, D).template triangularView<Eigen::Upper>();
        carry.col(D) = R.template block<D, 1>(D, 2 * D);
      }
      const double scale = Rii[i].diagonal().cwiseAbs().maxCoeff();
      if (!(Rii[i].diagonal().cwiseAbs().minCoeff() > 1e-14 * scale) || !(scale > 0.0)) {
        throw std::runtime_error(Where() + "state " + std::to_string(i) +
                                 " is not determined by the factors (singular R_ii)");
      }
    }
    auto solve_upper = [&](int i, const auto& rhs) {
      return Rii[i].template triangularView<Eigen::Upper>().solve(rhs).eval();
    };
    if (delta != nullptr) {
      delta->resize(n);
      (*delta)[n - 1] = -solve_upper(n - 1, rho[n - 1]);
      for (int i = n - 2; i >= 0; --i) {
        (*delta)[i] = -solve_upper(i, Vector(rho[i] + Rij[i] * (*delta)[i + 1]));
      }
    }
    if (covariance != nullptr || cross_covariance != nullptr) {
      std::vector<Block> local;
      std::vector<Block>* cov = covariance != nullptr ? covariance : &local;
      cov->resize(n);
      if (cross_covariance != nullptr) cross_covariance->resize(n - 1);
      auto own = [&](int i) {
        const Block Rinv = solve_upper(i, Block::Identity());
        return Block(Rinv * Rinv.transpose());
      };
      (*cov)[n - 1] = own(n - 1);
      for (int i = n - 2; i >= 0; --i) {
        const Block G = solve_upper(i, Rij[i]);
        const Block cross = -G * (*cov)[i + 1];
        (*cov)[i] = own(i) - cross * G.transpose();
        (*cov)[i] = 0.5 * ((*cov)[i] + (*cov)[i].transpose()).eval();
        if (cross_covariance != nullptr) (*cross_covariance)[i] = cross;
      }
    }
  }

 private:
  static std::string Where() { return std::string(__FILE__) + ": ChainSmoother: "; }

  std::vector<Rows> unary_;  // per state
  std::vector<Rows> pair_;   // per consecutive pair (i, i + 1)
};

}  // namespace ctlio::study
