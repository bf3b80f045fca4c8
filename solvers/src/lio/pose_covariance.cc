#include "ctlio/solvers/lio/pose_covariance.h"

#include <ceres/covariance.h>

#include <utility>
#include <vector>

#include "ctlio/solvers/lio/adaptive_covariance.h"

namespace ctlio::lio {

std::optional<Mat6> PoseCovariance(ceres::Problem* problem, const double* pose, const SE3& T_mr,
                                   const Mat6& tangent_from_body) {
  // Sparse QR of the window's Jacobian (the default options).
  ceres::Covariance covariance(ceres::Covariance::Options{});
  const std::vector<std::pair<const double*, const double*>> blocks = {{pose, pose}};
  if (!covariance.Compute(blocks, problem)) return std::nullopt;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
  if (!covariance.GetCovarianceBlockInTangentSpace(pose, pose, block.data())) return std::nullopt;
  const Mat6 M = T_mr.Adjoint() * tangent_from_body.inverse();
  return Mat6(M * Mat6(block) * M.transpose());
}

double LidarChiSquareScale(ceres::Problem* problem,
                           const std::vector<ceres::ResidualBlockId>& lidar) {
  double cost_sum = 0.0;
  int n = 0;
  for (const ceres::ResidualBlockId id : lidar) {
    const int m = problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    std::vector<double> r(static_cast<size_t>(m));
    double cost = 0.0;
    if (!problem->EvaluateResidualBlock(id, true, &cost, r.data(), nullptr)) continue;
    cost_sum += cost;
    n += m;
  }
  return n > 0 ? 2.0 * cost_sum / n : 1.0;
}

std::optional<Mat6> ScaledPoseCovariance(const SlidingWindow& window, StateId pose,
                                         const std::vector<ceres::ResidualBlockId>& lidar,
                                         double lidar_scale, const SE3& T_mr,
                                         const Mat6& tangent_from_body) {
  // One scaled group (the lidar blocks) and no prior rescaling: the adaptive model's general case.
  const std::optional<GroupScaledCovariance> c = GroupScaledPoseCovariance(
      window, pose, {ScaledGroup{lidar, lidar_scale}}, nullptr, 1.0, T_mr, tangent_from_body);
  if (!c) return std::nullopt;
  return c->scaled;
}

}  // namespace ctlio::lio
