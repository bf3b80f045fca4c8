#include "ctlio/solvers/lio/pose_covariance.h"

#include <ceres/covariance.h>

#include <set>
#include <utility>
#include <vector>

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
  std::vector<StateId> ordering;
  int offset = -1, n = 0;
  std::set<ceres::ResidualBlockId> others;
  for (const StateId id : window.StateIds()) {
    if (window.IsStateConstant(id)) continue;
    if (id == pose) offset = n;
    ordering.push_back(id);
    n += window.TangentSize(id);
    for (const ceres::ResidualBlockId r : window.ResidualBlocksOf(id)) others.insert(r);
  }
  if (offset < 0) return std::nullopt;
  for (const ceres::ResidualBlockId r : lidar) others.erase(r);
  Eigen::MatrixXd H, H_lidar;
  Eigen::VectorXd b;
  window.Linearize({others.begin(), others.end()}, ordering, &H, &b);
  window.Linearize(lidar, ordering, &H_lidar, &b);
  H += H_lidar / lidar_scale;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, 6);
  E.middleRows(offset, 6).setIdentity();
  const Mat6 block = E.transpose() * ldlt.solve(E);
  const Mat6 M = T_mr.Adjoint() * tangent_from_body.inverse();
  return Mat6(M * block * M.transpose());
}

}  // namespace ctlio::lio
