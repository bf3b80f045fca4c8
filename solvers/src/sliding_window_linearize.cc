// SlidingWindow::Linearize: the whitened, loss-corrected Jacobians of a set of residual blocks
// accumulated into the information form used by marginalisation and the covariance report.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "ctlio/solvers/sliding_window.h"
#include "sliding_window_internal.h"

namespace ctlio {
namespace {

using sliding_window_internal::IdList;
using sliding_window_internal::RowMajorMatrix;
using sliding_window_internal::Throw;

// Ceres' Corrector (Triggs et al., "Bundle adjustment — a modern synthesis", §4.3), applied in
// place to one residual block's residual r and tangent Jacobian J. See sliding_window.h.
void ApplyLoss(const ceres::LossFunction* loss, Eigen::VectorXd* r, RowMajorMatrix* J) {
  if (loss == nullptr) return;
  const double s = r->squaredNorm();
  double rho[3];
  loss->Evaluate(s, rho);
  if (!(rho[1] > 0.0) || !std::isfinite(rho[1])) {  // fully rejected: contributes nothing
    r->setZero();
    J->setZero();
    return;
  }
  const double sqrt_rho1 = std::sqrt(rho[1]);
  if (s == 0.0 || rho[2] <= 0.0) {
    *r *= sqrt_rho1;
    *J *= sqrt_rho1;
    return;
  }
  const double D = 1.0 + 2.0 * s * rho[2] / rho[1];
  const double alpha = 1.0 - std::sqrt(D);
  // Jacobian first: it uses the uncorrected residual.
  const Eigen::RowVectorXd rTJ = r->transpose() * (*J);
  *J = sqrt_rho1 * (*J - (alpha / s) * (*r) * rTJ);
  *r *= sqrt_rho1 / (1.0 - alpha);
}

}  // namespace

// Residual blocks on the same tuple of states (e.g. the 1,000 lidar residuals of one knot
// interval) are accumulated into one dense local information matrix by symmetric rank updates and
// scattered into H once per tuple; PlusJacobians are computed once per state.
void SlidingWindow::Linearize(const std::vector<ceres::ResidualBlockId>& residuals,
                              const std::vector<StateId>& ordering, Eigen::MatrixXd* H,
                              Eigen::VectorXd* b) const {
  struct StateInfo {
    const StateBlock* block = nullptr;
    int offset = -1;  // row in H, -1 if not in the ordering (then it must be constant)
    RowMajorMatrix plus;
    bool plus_ready = false;
  };
  std::unordered_map<StateId, StateInfo> info;
  int n = 0;
  for (StateId id : ordering) {
    StateInfo& s = info[id];
    if (s.block != nullptr) Throw(__LINE__, "state " + std::to_string(id) + " twice");
    s.block = &Get(id, __LINE__);
    s.offset = n;
    n += s.block->tangent_size;
  }
  // The rows of a group's residuals are gathered and added to its H and b a block of rows at a
  // time: one rank-k update (Eigen's blocked product) instead of a rank-1 update per lidar point,
  // which was a third of the linearisation's instructions.
  constexpr int kRowsPerUpdate = 64;
  struct Group {
    std::vector<StateInfo*> states;
    Eigen::MatrixXd H;  // lower triangle accumulated
    Eigen::VectorXd b;
    RowMajorMatrix rows;     // pending rows of whitened, loss-corrected Jacobians
    Eigen::VectorXd rows_r;  // and their residuals
    int pending = 0;
    void Flush() {
      if (pending == 0) return;
      const auto J = rows.topRows(pending);
      H.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
      b.noalias() += J.transpose() * rows_r.head(pending);
      pending = 0;
    }
  };
  std::map<std::vector<StateId>, Group> groups;

  // The residuals are evaluated here, not by Ceres: run the shared preparation at the current
  // estimate ourselves (the factors would otherwise interpolate each point on their own).
  shared_interpolations_->PrepareForEvaluation(true, true);
  std::vector<const double*> parameters;
  std::vector<double*> jacobians;
  std::vector<RowMajorMatrix> ambient;
  Eigen::VectorXd r;
  RowMajorMatrix J;
  for (ceres::ResidualBlockId rid : residuals) {
    const std::vector<StateId>& ids = StatesOf(rid);
    auto [group_it, inserted] = groups.try_emplace(ids);
    Group& group = group_it->second;
    int width = 0;
    if (inserted) {
      for (StateId id : ids) {
        StateInfo& s = info[id];
        if (s.block == nullptr) {
          s.block = &Get(id, __LINE__);
          if (!problem_->IsParameterBlockConstant(s.block->values.get())) {
            Throw<std::logic_error>(__LINE__, "residual touches state " + std::to_string(id) +
                                                  " which is neither in the ordering nor constant");
          }
        }
        group.states.push_back(&s);
        if (s.offset >= 0) width += s.block->tangent_size;
      }
      group.H.setZero(width, width);
      group.b.setZero(width);
    }
    width = static_cast<int>(group.b.size());
    const ceres::CostFunction* cost = problem_->GetCostFunctionForResidualBlock(rid);
    const int m = cost->num_residuals();
    const size_t k = ids.size();
    parameters.resize(k);
    jacobians.resize(k);
    if (ambient.size() < k) ambient.resize(k);
    for (size_t i = 0; i < k; ++i) {
      const StateInfo& s = *group.states[i];
      parameters[i] = s.block->values.get();
      if (s.offset >= 0) {
        ambient[i].resize(m, s.block->ambient_size);
        jacobians[i] = ambient[i].data();
      } else {
        jacobians[i] = nullptr;  // constant state: Ceres' contract allows a null Jacobian
      }
    }
    r.resize(m);
    if (!cost->Evaluate(parameters.data(), r.data(), jacobians.data())) {
      Throw<std::runtime_error>(__LINE__, "a residual block on states (" + IdList(ids) +
                                              ") failed to evaluate at the current estimate");
    }
    // Tangent Jacobian [J₁·P₁, J₂·P₂, …] (P = PlusJacobian) over the ordered states.
    J.resize(m, width);
    int c = 0;
    for (size_t i = 0; i < k; ++i) {
      StateInfo& s = *group.states[i];
      if (s.offset < 0) continue;
      const int t = s.block->tangent_size;
      if (s.block->manifold == nullptr) {
        J.middleCols(c, t) = ambient[i];
      } else {
        if (!s.plus_ready) {
          s.plus.resize(s.block->ambient_size, t);
          s.block->manifold->PlusJacobian(s.block->values.get(), s.plus.data());
          s.plus_ready = true;
        }
        // Coefficient-based product: these are tiny (m×7 · 7×6), GEMM's blocking only costs.
        J.middleCols(c, t).noalias() = ambient[i].lazyProduct(s.plus);
      }
      c += t;
    }
    if (!r.allFinite() || !J.allFinite()) {
      Throw<std::runtime_error>(__LINE__, "a residual block on states (" + IdList(ids) +
                                              ") is NaN/Inf at the current estimate");
    }
    ApplyLoss(problem_->GetLossFunctionForResidualBlock(rid), &r, &J);
    if (group.pending + m > group.rows.rows()) {
      group.Flush();
      if (m > group.rows.rows()) {
        group.rows.resize(std::max(m, kRowsPerUpdate), width);
        group.rows_r.resize(group.rows.rows());
      }
    }
    group.rows.middleRows(group.pending, m) = J;
    group.rows_r.segment(group.pending, m) = r;
    group.pending += m;
  }
  for (auto& [ids, group] : groups) group.Flush();

  H->setZero(n, n);
  b->setZero(n);
  for (auto& [ids, group] : groups) {
    group.H.triangularView<Eigen::StrictlyUpper>() = group.H.transpose();
    int ci = 0;
    for (const StateInfo* si : group.states) {
      if (si->offset < 0) continue;
      const int ti = si->block->tangent_size;
      b->segment(si->offset, ti) += group.b.segment(ci, ti);
      int cj = 0;
      for (const StateInfo* sj : group.states) {
        if (sj->offset < 0) continue;
        const int tj = sj->block->tangent_size;
        H->block(si->offset, sj->offset, ti, tj) += group.H.block(ci, cj, ti, tj);
        cj += tj;
      }
      ci += ti;
    }
  }
}

}  // namespace ctlio
