// SlidingWindow: the one windowed-problem component every ctlio estimator runs on (SPEC §5).
//
// The window owns states (parameter blocks keyed by an int64 id, e.g. a timestamp in ns, each
// with its manifold), owns the Ceres residual blocks on them and knows which residual touches
// which state. Solve() runs Ceres (SPARSE_NORMAL_CHOLESKY + SuiteSparse by default; every solver
// option is exposed). Marginalize(ids) removes states by Schur complement:
//
//   1. every residual block touching a leaving state is linearised at the current estimate:
//      tangent Jacobians J·PlusJacobian (the solver's own convention), with the loss function
//      applied through the same Triggs correction Ceres uses (ceres/internal/corrector.cc):
//      s = ‖r‖², ρ = loss(s); if s = 0 or ρ'' ≤ 0:  r ← √ρ'·r, J ← √ρ'·J;
//      else α = 1 − √(1 + 2sρ''/ρ'), r ← √ρ'/(1 − α)·r, J ← √ρ'·(I − α·r̂r̂ᵀ)·J (r̂ = r/‖r‖),
//      so that the marginal is the Gauss–Newton model Ceres itself minimises. A residual whose
//      loss has ρ' ≤ 0 (fully rejected outlier) contributes nothing (Ceres would divide by 0);
//   2. H = ΣJᵀJ, b = ΣJᵀr over [leaving states; kept states those residuals touch]
//      (dense: windows are small);
//   3. Schur complement onto the kept states (schur_complement.h: pseudo-inverse of the leaving
//      block, so a singular block — an unobserved direction — never yields NaN);
//   4. the residuals and the leaving states are removed and replaced by ONE MarginalizationPrior
//      r = √Λ·(x ⊟ x̄) + r0 on the kept states, x̄ = their current values (first-estimate
//      Jacobians, factors/priors/marginalization_prior.h).
//
// Documented edge cases (all throw std::invalid_argument / std::logic_error with file:line):
//   - unknown or duplicate ids, an empty id list, an empty window: throw;
//   - a leaving state that no residual touches ("disconnected"): it carries no information about
//     the others, so it is simply removed (exact); no prior is added if nothing is connected;
//   - a Schur complement of rank 0 (leaving states only connected among themselves): no prior;
//   - residual evaluation failing or returning NaN/Inf at the current estimate: throws
//     std::runtime_error and leaves the window unchanged.
//
// Shared work (SPEC §4: the interpolated pose of one lidar firing, read by all its points) is
// registered with shared_interpolations(), the problem's ceres::EvaluationCallback; Linearize (and
// so Marginalize and Covariance) runs the same preparation before it evaluates the residuals
// itself, outside Ceres' evaluation loop.
//
// States may use nullptr (Euclidean), ctlio::PoseManifold or ctlio::RotationManifold; any other
// manifold is rejected by AddState, because MarginalizationPrior needs the exact derivative of
// Minus away from x̄ (see marginalization_prior.h).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/schur_complement.h"
#include "ctlio/solvers/shared_interpolation_callback.h"

namespace ctlio {

class MarginalizationPrior;
using StateId = std::int64_t;

struct SlidingWindowOptions {
  SlidingWindowOptions();
  // Defaults: SPARSE_NORMAL_CHOLESKY with SUITE_SPARSE, Levenberg–Marquardt, 50 iterations,
  // 1 thread, silent. Change freely.
  ceres::Solver::Options solver;
  // Eigenvalue cut-off of the Jacobi-scaled pseudo-inverse and square root
  // (schur_complement.h).
  double relative_eigenvalue_threshold = kDefaultRelativeEigenvalueThreshold;
  // Threads of the window's own per-evaluation work, on ParallelFor's persistent helpers: the
  // shared interpolations (SharedInterpolationCallback) and the rows of batched lidar blocks
  // (ContinuousPointToPlaneBatch::set_row_runner). Independent of solver.num_threads (Ceres' own
  // threads, which evaluate residual blocks in parallel); the same estimates for any count.
  int threads = 1;
};

struct MarginalizationReport {
  std::vector<StateId> marginalized;  // ids removed
  std::vector<StateId> kept;          // kept states the new prior is on (ascending ids)
  int removed_residual_blocks = 0;    // residual blocks linearised and removed
  int marginalized_dimension = 0;     // Σ tangent sizes of the removed states
  int marginalized_rank = 0;          // rank of their information block (< dimension: singular)
  int prior_rank = 0;                 // rows of the new prior; 0 ⇒ no prior was added
  ceres::ResidualBlockId prior = nullptr;
};

class SlidingWindow {
 public:
  explicit SlidingWindow(const SlidingWindowOptions& options = SlidingWindowOptions());
  ~SlidingWindow();
  SlidingWindow(const SlidingWindow&) = delete;
  SlidingWindow& operator=(const SlidingWindow&) = delete;

  // ---- States -------------------------------------------------------------------------------
  // Copies `initial` (ambient_size doubles) into window-owned storage and returns its stable
  // address. manifold: nullptr = Euclidean, or a ctlio::PoseManifold / RotationManifold (shared).
  double* AddState(StateId id, const double* initial, int ambient_size,
                   std::shared_ptr<const ceres::Manifold> manifold = nullptr);
  double* AddPoseState(StateId id, const SE3& T);                // 7 doubles, PoseManifold
  double* AddRotationState(StateId id, const Mat3& C);           // 4 doubles, RotationManifold
  double* AddVectorState(StateId id, const Eigen::VectorXd& v);  // Euclidean
  // Removes a state and every residual block on it WITHOUT keeping its information.
  void RemoveState(StateId id);

  bool HasState(StateId id) const { return states_.count(id) != 0; }
  double* State(StateId id);
  const double* State(StateId id) const;
  SE3 Pose(StateId id) const;                // for a PoseManifold state
  Eigen::VectorXd Vector(StateId id) const;  // the ambient values of any state
  int AmbientSize(StateId id) const;
  int TangentSize(StateId id) const;
  const ceres::Manifold* Manifold(StateId id) const;  // nullptr for Euclidean
  std::vector<StateId> StateIds() const;              // ascending
  int num_states() const { return static_cast<int>(states_.size()); }
  // Constant states are not optimised; Covariance() conditions on them (treats them as known).
  void SetStateConstant(StateId id, bool constant);
  bool IsStateConstant(StateId id) const;

  // ---- Residual blocks ----------------------------------------------------------------------
  // Takes ownership of cost and loss (like ceres::Problem; a loss may be shared). The cost's
  // parameter blocks are the listed states in order.
  ceres::ResidualBlockId AddResidualBlock(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                          const std::vector<StateId>& states);
  void RemoveResidualBlock(ceres::ResidualBlockId id);
  int num_residual_blocks() const { return static_cast<int>(residuals_.size()); }
  std::vector<ceres::ResidualBlockId> ResidualBlocksOf(StateId id) const;
  const std::vector<StateId>& StatesOf(ceres::ResidualBlockId id) const;

  // ---- Estimation ---------------------------------------------------------------------------
  // Throws std::logic_error on an empty window.
  ceres::Solver::Summary Solve();
  // True while Solve() runs: the window's options().threads serve its solve only (with the
  // odometry's window.overlap the marginalisation runs on a second thread beside the next scan's
  // preprocessing, where more threads would only contend for the cores).
  bool solving() const { return solving_; }
  MarginalizationReport Marginalize(const std::vector<StateId>& ids);
  // The marginal priors forget what they say about the listed states, which stay: every prior
  // Marginalize left (not a MarginalizationPrior the caller added) on any of them is replaced by
  // one prior on its other states, the Schur complement of the priors' information (linearised at
  // the current estimate) over the listed states' coordinates, i.e. the other states' marginal.
  // Residual blocks that are not marginal priors are kept as they are. Why: information
  // marginalised while a static state (a calibration) was far off was linearised there and stays so
  // (first-estimate Jacobians); with it forgotten, the state is estimated from the residuals kept
  // or added after, linearised near its current value. Report: `marginalized` the listed states the
  // priors touched, `kept` the new prior's states, `removed_residual_blocks` the priors replaced;
  // nothing changes and the report is empty when no marginal prior touches them. Throws for unknown
  // or repeated ids.
  MarginalizationReport ForgetInformation(const std::vector<StateId>& ids);

  // Joint marginal covariance (tangent spaces, in the order of `ids`) of the listed states under
  // the Gauss–Newton model of the whole window at the current estimate: the pseudo-inverse of the
  // dense information of all non-constant states (loss functions applied as in Marginalize).
  Eigen::MatrixXd Covariance(const std::vector<StateId>& ids) const;

  // Linearised information (H, b = Jᵀr) of the given residual blocks over the given states
  // (tangent spaces, in that order; residuals may only touch listed or constant states).
  void Linearize(const std::vector<ceres::ResidualBlockId>& residuals,
                 const std::vector<StateId>& ordering, Eigen::MatrixXd* H,
                 Eigen::VectorXd* b) const;

  // The problem's evaluation callback: register the shared interpolation of every firing that a
  // residual of this window reads (ContinuousPointToPlane).
  SharedInterpolationCallback& shared_interpolations() { return *shared_interpolations_; }

  SlidingWindowOptions& options() { return options_; }
  // The underlying problem, for what the window does not wrap (e.g. parameter bounds). Adding or
  // removing blocks through it bypasses the window's bookkeeping: do not.
  ceres::Problem& problem() { return *problem_; }

 private:
  struct StateBlock {
    std::unique_ptr<double[]> values;
    int ambient_size = 0;
    int tangent_size = 0;
    std::shared_ptr<const ceres::Manifold> manifold;
    std::set<ceres::ResidualBlockId> residuals;
  };
  // `residuals` sorted by the order they were added (not by address), so that sums over them and
  // Ceres' order after removals do not depend on the heap layout.
  std::vector<ceres::ResidualBlockId> InAddedOrder(
      const std::set<ceres::ResidualBlockId>& residuals) const;
  // The prior `residuals` (linearised at the current estimate) leave on report->kept once
  // report->marginalized are integrated out (Schur complement, steps 2–4 above), at the kept
  // states' current values; fills report's ranks. nullptr when nothing is kept or of rank 0.
  std::unique_ptr<MarginalizationPrior> SchurPrior(
      const std::vector<ceres::ResidualBlockId>& residuals, MarginalizationReport* report) const;
  const StateBlock& Get(StateId id, int line) const;
  StateBlock& Get(StateId id, int line);

  SlidingWindowOptions options_;
  bool solving_ = false;
  std::unique_ptr<SharedInterpolationCallback> shared_interpolations_;  // outlives problem_
  std::unique_ptr<ceres::Problem> problem_;
  std::map<StateId, StateBlock> states_;
  std::unordered_map<ceres::ResidualBlockId, std::vector<StateId>> residuals_;
  // Order in which the residual blocks were added: Marginalize sums their linearisations in this
  // order, not in the order of their addresses, so that its result does not depend on the heap.
  std::unordered_map<ceres::ResidualBlockId, uint64_t> residual_serial_;
  uint64_t next_residual_serial_ = 0;
  // The priors Marginalize and ForgetInformation added (not a caller's MarginalizationPrior).
  std::set<ceres::ResidualBlockId> marginal_priors_;
};

}  // namespace ctlio
