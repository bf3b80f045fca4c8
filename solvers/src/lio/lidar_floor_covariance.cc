#include "ctlio/solvers/lio/lidar_floor_covariance.h"

#include <algorithm>
#include <iterator>
#include <map>
#include <set>

namespace ctlio::lio {

Mat6 FlooredInformation(const Mat6& H_c, const Mat6& floor) {
  // (I + Σ_c·H_c) has eigenvalues ≥ 1 (Σ_c·H_c is similar to the PSD H_c^½·Σ_c·H_c^½): always
  // invertible. H_c·(I + Σ_c·H_c)⁻¹ = (I + H_c·Σ_c)⁻¹·H_c: symmetrised against round-off.
  const Mat6 A = Mat6::Identity() + floor * H_c;
  const Mat6 H = A.transpose().partialPivLu().solve(H_c);
  return 0.5 * (H + H.transpose());
}

namespace {

// The window's dense information with the lidar blocks floored ((1) at `offset`, or divided by
// c alone when they reach other states); the blocks in `skip` left out.
Eigen::MatrixXd FlooredInformationMatrix(const SlidingWindow& window,
                                         const std::vector<StateId>& ordering,
                                         const std::set<ceres::ResidualBlockId>& others, int offset,
                                         const std::vector<ceres::ResidualBlockId>& lidar,
                                         double lidar_scale, const Vec6& floor_sigma,
                                         const Mat6& tangent_from_body) {
  Eigen::MatrixXd H, H_l;
  Eigen::VectorXd b;
  window.Linearize({others.begin(), others.end()}, ordering, &H, &b);
  if (lidar.empty()) return H;
  window.Linearize(lidar, ordering, &H_l, &b);
  H_l /= lidar_scale;
  // The lidar's information outside the pose block (another knot of a continuous-time scan):
  // then (1) has no single pose to floor, and c alone is applied.
  Eigen::MatrixXd outside = H_l;
  outside.block(offset, offset, 6, 6).setZero();
  const double size = H_l.block(offset, offset, 6, 6).cwiseAbs().maxCoeff();
  if (outside.cwiseAbs().maxCoeff() <= 1e-12 * size) {
    // State tangent δ_state = A·δ_body: H_body = Aᵀ·H_state·A, and back with A⁻¹.
    const Mat6& A = tangent_from_body;
    const Mat6 A_inv = A.inverse();
    const Mat6 H_body = A.transpose() * Mat6(H_l.block(offset, offset, 6, 6)) * A;
    const Mat6 floor = floor_sigma.cwiseAbs2().asDiagonal();
    H_l.block(offset, offset, 6, 6) = A_inv.transpose() * FlooredInformation(H_body, floor) * A_inv;
  }
  return H + H_l;
}

struct Layout {
  std::vector<StateId> ordering;
  std::map<StateId, int> offset;
  int n = 0;
  std::set<ceres::ResidualBlockId> blocks;                        // every block of the window
  std::map<ceres::ResidualBlockId, std::set<StateId>> states_of;  // its non-constant states
  int pose_offset = 0;                                            // of the newest pose
};

Layout WindowLayout(const SlidingWindow& window) {
  Layout l;
  for (const StateId id : window.StateIds()) {
    if (window.IsStateConstant(id)) continue;
    l.ordering.push_back(id);
    l.offset[id] = l.n;
    l.n += window.TangentSize(id);
    for (const ceres::ResidualBlockId r : window.ResidualBlocksOf(id)) {
      l.blocks.insert(r);
      l.states_of[r].insert(id);
    }
  }
  return l;
}

// The layout of the window's free states and its blocks but the scan's lidar ones; empty if the
// newest pose is not a free 6-dof state.
std::optional<Layout> LayoutWithoutLidar(const SlidingWindow& window, StateId pose,
                                         const std::vector<ceres::ResidualBlockId>& lidar) {
  Layout l = WindowLayout(window);
  const auto at = l.offset.find(pose);
  if (at == l.offset.end() || window.TangentSize(pose) != 6) return std::nullopt;
  l.pose_offset = at->second;
  for (const ceres::ResidualBlockId r : lidar) l.blocks.erase(r);
  return l;
}

std::optional<Mat6> NewestPose(const Eigen::LDLT<Eigen::MatrixXd>& ldlt, int n, int offset,
                               const SE3& T_mr, const Mat6& tangent_from_body) {
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, 6);
  E.middleRows(offset, 6).setIdentity();
  const Mat6 M = T_mr.Adjoint() * tangent_from_body.inverse();
  return Mat6(M * Mat6(E.transpose() * ldlt.solve(E)) * M.transpose());
}

}  // namespace

std::optional<Mat6> FlooredLidarPoseCovariance(const SlidingWindow& window, StateId pose,
                                               const std::vector<ceres::ResidualBlockId>& lidar,
                                               double lidar_scale, const Vec6& floor_sigma,
                                               const SE3& T_mr, const Mat6& tangent_from_body) {
  // A recursion that has carried nothing yet uses the window's prior: this scan alone.
  return FlooredPoseCovariance().Compute(window, pose, {}, lidar, lidar_scale, floor_sigma, T_mr,
                                         tangent_from_body);
}

std::optional<Mat6> FlooredPoseCovariance::Compute(const SlidingWindow& window, StateId pose,
                                                   const std::vector<StateId>& newest_states,
                                                   const std::vector<ceres::ResidualBlockId>& lidar,
                                                   double lidar_scale, const Vec6& floor_sigma,
                                                   const SE3& T_mr, const Mat6& tangent_from_body) {
  std::optional<Layout> layout = LayoutWithoutLidar(window, pose, lidar);
  if (!layout) return std::nullopt;
  Layout& l = *layout;
  // The carried prior applies when all its states are still free in the window and the newest
  // pose is not among them; every block on those states alone is then already in it.
  used_carried_ = !carried_states_.empty();  // the newest pose is free: LayoutWithoutLidar
  for (const StateId id : carried_states_) {
    if (l.offset.count(id) == 0 || id == pose) used_carried_ = false;
  }
  if (used_carried_) {
    const std::set<StateId> carried(carried_states_.begin(), carried_states_.end());
    for (auto it = l.blocks.begin(); it != l.blocks.end();) {
      bool inside = true;
      for (const StateId id : l.states_of[*it]) inside = inside && carried.count(id) > 0;
      it = inside ? l.blocks.erase(it) : std::next(it);
    }
  }
  Eigen::MatrixXd H = FlooredInformationMatrix(window, l.ordering, l.blocks, l.pose_offset, lidar,
                                               lidar_scale, floor_sigma, tangent_from_body);
  if (used_carried_) {
    int i0 = 0;
    for (const StateId a : carried_states_) {
      int j0 = 0;
      const int na = window.TangentSize(a);
      for (const StateId b : carried_states_) {
        const int nb = window.TangentSize(b);
        H.block(l.offset[a], l.offset[b], na, nb) += carried_.block(i0, j0, na, nb);
        j0 += nb;
      }
      i0 += na;
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    carried_states_.clear();
    return std::nullopt;
  }
  // The next scan's prior: the newest states' marginal information, (Eᵀ·H⁻¹·E)⁻¹.
  std::vector<StateId> next;
  for (const StateId id : newest_states) {
    if (l.offset.count(id) > 0) next.push_back(id);
  }
  std::sort(next.begin(), next.end());
  int m = 0;
  for (const StateId id : next) m += window.TangentSize(id);
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(l.n, m);
  int k = 0;
  for (const StateId id : next) {
    E.block(l.offset[id], k, window.TangentSize(id), window.TangentSize(id)).setIdentity();
    k += window.TangentSize(id);
  }
  const Eigen::MatrixXd S = E.transpose() * ldlt.solve(E);
  const Eigen::LDLT<Eigen::MatrixXd> inv(S);
  if (m > 0 && inv.info() == Eigen::Success && inv.isPositive()) {
    carried_ = inv.solve(Eigen::MatrixXd::Identity(m, m));
    carried_ = 0.5 * (carried_ + carried_.transpose()).eval();
    carried_states_ = next;
  } else {
    carried_states_.clear();
  }
  return NewestPose(ldlt, l.n, l.pose_offset, T_mr, tangent_from_body);
}

}  // namespace ctlio::lio
