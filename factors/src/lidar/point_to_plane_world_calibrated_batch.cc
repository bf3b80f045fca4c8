#include "ctlio/factors/lidar/point_to_plane_world_calibrated_batch.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "ctlio/factors/lidar/batch_square_root.h"

namespace ctlio {

PointToPlaneWorldCalibratedBatch::PointToPlaneWorldCalibratedBatch(
    std::vector<Point> points, double offset_anchor,
    std::shared_ptr<const ceres::LossFunction> loss, bool extrinsic_block, bool offset_block,
    const SE3& fixed_T_rl, Form form)
    : points_(std::move(points)),
      offset_anchor_(offset_anchor),
      loss_(std::move(loss)),
      extrinsic_(extrinsic_block),
      offset_(offset_block),
      fixed_T_rl_(fixed_T_rl),
      form_(form) {
  if (points_.empty()) throw std::invalid_argument("PointToPlaneWorldCalibratedBatch: no points");
  const int n = static_cast<int>(points_.size());
  set_num_residuals(form_ == Form::kSquareRoot ? tangent_size() + 1
                                               : n + (loss_ != nullptr ? 1 : 0));
  mutable_parameter_block_sizes()->push_back(7);
  if (extrinsic_) mutable_parameter_block_sizes()->push_back(7);
  if (offset_) mutable_parameter_block_sizes()->push_back(1);
}

bool PointToPlaneWorldCalibratedBatch::Evaluate(double const* const* parameters, double* residuals,
                                                double** jacobians) const {
  using Row6 = PointToPlaneWorldCalibrated::Row6;
  const size_t n = points_.size();
  const int w = tangent_size();
  const int rl_block = extrinsic_ ? 1 : -1;
  const int delta_block = offset_ ? (extrinsic_ ? 2 : 1) : -1;
  const int delta_column = extrinsic_ ? 12 : 6;  // δ's tangent coordinate
  const SE3 T_wb = PoseManifold::Pose(parameters[0]);
  const SE3 T_rl = extrinsic_ ? PoseManifold::Pose(parameters[rl_block]) : fixed_T_rl_;
  const double epsilon = offset_ ? offset_anchor_ - parameters[delta_block][0] : 0.0;
  bool want = false;
  if (jacobians != nullptr) {
    for (int b = 0; b < static_cast<int>(parameter_block_sizes().size()); ++b) {
      want = want || jacobians[b] != nullptr;
    }
  }
  const bool square_root = form_ == Form::kSquareRoot;
  // Square-root form: JᵀJ (lower), Jᵀr and ‖r‖² of the point rows, plus Σ ρ − ρ'·e².
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  if (square_root && want) {
    H.setZero(w, w);
    g.setZero(w);
  }
  Eigen::VectorXd row(w);
  double squares = 0.0, gaps = 0.0;
  Row6 J_wb, J_rl;
  double J_delta = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Point& p = points_[i];
    const SE3 E = offset_ ? SE3::Exp(epsilon * p.twist) : SE3();
    const double e = PointToPlaneWorldCalibrated::EvaluateTangent(
        p.association, p.point_lidar, p.deskew, p.twist, T_wb, T_rl, E, want ? &J_wb : nullptr,
        want && extrinsic_ ? &J_rl : nullptr, want && offset_ ? &J_delta : nullptr);
    double scale = 1.0;
    if (loss_ != nullptr) {
      double rho[3];
      loss_->Evaluate(e * e, rho);
      if (rho[2] > 0.0) return false;  // not concave here: no exact constant row
      scale = std::sqrt(rho[1]);
      gaps += rho[0] - rho[1] * e * e;
    }
    const double r = scale * e;
    if (square_root) {
      squares += r * r;
      if (!want) continue;
      row.head<6>() = scale * J_wb.transpose();
      if (extrinsic_) row.segment<6>(6) = scale * J_rl.transpose();
      if (offset_) row[delta_column] = scale * J_delta;
      H.selfadjointView<Eigen::Lower>().rankUpdate(row);
      g += r * row;
      continue;
    }
    residuals[i] = r;
    if (!want) continue;
    if (jacobians[0] != nullptr) {
      LiftPoseJacobian<1>(Row6(scale * J_wb), parameters[0], jacobians[0] + 7 * i);
    }
    if (extrinsic_ && jacobians[rl_block] != nullptr) {
      LiftPoseJacobian<1>(Row6(scale * J_rl), parameters[rl_block], jacobians[rl_block] + 7 * i);
    }
    if (offset_ && jacobians[delta_block] != nullptr) jacobians[delta_block][i] = scale * J_delta;
  }
  if (!square_root) {
    if (loss_ == nullptr) return true;
    residuals[n] = std::sqrt(std::max(gaps, 0.0));  // clamps rounding below 0 only
    if (!want) return true;
    for (int b = 0; b < static_cast<int>(parameter_block_sizes().size()); ++b) {
      if (jacobians[b] == nullptr) continue;
      const int size = parameter_block_sizes()[static_cast<size_t>(b)];
      std::fill_n(jacobians[b] + n * static_cast<size_t>(size), size, 0.0);
    }
    return true;
  }
  const double cost = squares + gaps;  // twice the robust cost
  if (!want) {
    std::fill_n(residuals, w, 0.0);
    residuals[w] = std::sqrt(cost);
    return true;
  }
  Eigen::MatrixXd R;
  Eigen::VectorXd r0;
  if (!BatchSquareRoot(&H, g, kPivotThreshold, &R, &r0)) return false;
  std::copy_n(r0.data(), w, residuals);
  residuals[w] = std::sqrt(std::max(cost - r0.squaredNorm(), 0.0));  // clamps rounding only
  for (int j = 0; j <= w; ++j) {
    // The constant last row has no Jacobian.
    const Eigen::VectorXd R_j =
        j < w ? Eigen::VectorXd(R.row(j).transpose()) : Eigen::VectorXd(Eigen::VectorXd::Zero(w));
    if (jacobians[0] != nullptr) {
      LiftPoseJacobian<1>(Row6(R_j.head<6>().transpose()), parameters[0], jacobians[0] + 7 * j);
    }
    if (extrinsic_ && jacobians[rl_block] != nullptr) {
      LiftPoseJacobian<1>(Row6(R_j.segment<6>(6).transpose()), parameters[rl_block],
                          jacobians[rl_block] + 7 * j);
    }
    if (offset_ && jacobians[delta_block] != nullptr) {
      jacobians[delta_block][j] = R_j[delta_column];
    }
  }
  return true;
}

}  // namespace ctlio
