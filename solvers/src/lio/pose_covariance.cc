#include "ctlio/solvers/lio/pose_covariance.h"

#include <ceres/covariance.h>

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

}  // namespace ctlio::lio
