#include "ctlio/solvers/lio/misfit_covariance.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "ctlio/solvers/chi_square.h"
#include "ctlio/solvers/lio/adaptive_covariance.h"

namespace ctlio::lio {

double MisfitFactor(double chi2, int dof) {
  if (dof <= 0 || !std::isfinite(chi2)) return 1.0;
  const double reduced = chi2 / dof;
  return reduced > 1.0 && chi2 > ChiSquareQuantile(dof, 0.999) ? reduced : 1.0;
}

std::vector<ceres::ResidualBlockId> MotionModelBlocks(
    const SlidingWindow& window, const std::vector<StateId>& newest,
    const std::vector<ceres::ResidualBlockId>& lidar, ceres::ResidualBlockId prior) {
  std::set<ceres::ResidualBlockId> blocks;
  for (const StateId id : newest) {
    if (!window.HasState(id)) continue;
    for (const ceres::ResidualBlockId r : window.ResidualBlocksOf(id)) blocks.insert(r);
  }
  for (const ceres::ResidualBlockId r : lidar) blocks.erase(r);
  blocks.erase(prior);
  return {blocks.begin(), blocks.end()};
}

std::optional<Mat6> MisfitCovarianceIncrease(const SlidingWindow& window, StateId pose,
                                             const std::vector<ceres::ResidualBlockId>& lidar,
                                             double lidar_scale,
                                             const std::vector<ScaledGroup>& released,
                                             const SE3& T_mr, const Mat6& tangent_from_body) {
  std::vector<ScaledGroup> held_groups{ScaledGroup{lidar, lidar_scale}};
  std::vector<ScaledGroup> released_groups = held_groups;
  bool any = false;
  for (const ScaledGroup& g : released) {
    if (g.blocks.empty()) continue;
    held_groups.push_back(ScaledGroup{g.blocks, 1.0});
    released_groups.push_back(g);
    any = any || g.scale > 1.0;
  }
  if (!any) return Mat6::Zero();
  const std::optional<GroupScaledCovariance> held =
      GroupScaledPoseCovariance(window, pose, held_groups, nullptr, 1.0, T_mr, tangent_from_body);
  const std::optional<GroupScaledCovariance> freed = GroupScaledPoseCovariance(
      window, pose, released_groups, nullptr, 1.0, T_mr, tangent_from_body);
  if (!held || !freed) return std::nullopt;
  const Mat6 d = freed->scaled - held->scaled;
  return 0.5 * (d + d.transpose());
}

}  // namespace ctlio::lio
