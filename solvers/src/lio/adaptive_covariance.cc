#include "ctlio/solvers/lio/adaptive_covariance.h"

#include <ceres/cost_function.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

namespace ctlio::lio {

namespace {

bool EvaluateResiduals(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& blocks,
                       std::vector<double>* r) {
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = blocks;
  options.apply_loss_function = false;
  return problem->Evaluate(options, nullptr, r, nullptr, nullptr);
}

}  // namespace

double RobustResidualVariance(ceres::Problem* problem,
                              const std::vector<ceres::ResidualBlockId>& blocks) {
  if (blocks.empty()) return 1.0;
  std::vector<double> r;
  if (!EvaluateResiduals(problem, blocks, &r) || r.empty()) return 1.0;
  for (double& v : r) v = std::abs(v);
  auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  // 1.4826 = 1/Φ⁻¹(3/4): the MAD of a zero-mean Gaussian is 0.6745σ.
  const double sigma = 1.4826 * *mid;
  return sigma * sigma;
}

GroupChiSquare EvaluateGroupChiSquare(ceres::Problem* problem,
                                      const std::vector<ceres::ResidualBlockId>& blocks) {
  GroupChiSquare out;
  if (blocks.empty()) return out;
  std::vector<double> r;
  if (!EvaluateResiduals(problem, blocks, &r)) {
    out.chi2 = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  out.n = static_cast<int>(r.size());
  for (const double v : r) out.chi2 += v * v;
  return out;
}

std::optional<GroupScaledCovariance> GroupScaledPoseCovariance(
    const SlidingWindow& window, StateId pose, const std::vector<ScaledGroup>& groups,
    ceres::ResidualBlockId prior, double prior_scale, const SE3& T_mr,
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
  for (const ScaledGroup& g : groups) {
    for (const ceres::ResidualBlockId r : g.blocks) others.erase(r);
  }
  const bool has_prior = prior != nullptr && others.erase(prior) > 0;
  Eigen::MatrixXd H1, H_s, H_g;
  Eigen::VectorXd b;
  window.Linearize({others.begin(), others.end()}, ordering, &H1, &b);
  H_s = H1;
  if (has_prior) {
    window.Linearize({prior}, ordering, &H_g, &b);
    H1 += H_g;
    H_s += H_g / prior_scale;
  }
  std::vector<Eigen::MatrixXd> H_groups;
  for (const ScaledGroup& g : groups) {
    window.Linearize(g.blocks, ordering, &H_g, &b);
    H1 += H_g;
    H_s += H_g / g.scale;
    H_groups.push_back(H_g / g.scale);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt1(H1), ldlt_s(H_s);
  if (ldlt1.info() != Eigen::Success || !ldlt1.isPositive()) return std::nullopt;
  if (ldlt_s.info() != Eigen::Success || !ldlt_s.isPositive()) return std::nullopt;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, 6);
  E.middleRows(offset, 6).setIdentity();
  const Mat6 M = T_mr.Adjoint() * tangent_from_body.inverse();
  GroupScaledCovariance out;
  out.unscaled = M * Mat6(E.transpose() * ldlt1.solve(E)) * M.transpose();
  out.scaled = M * Mat6(E.transpose() * ldlt_s.solve(E)) * M.transpose();
  for (const Eigen::MatrixXd& Hg : H_groups) out.trace_share.push_back(ldlt_s.solve(Hg).trace());
  return out;
}

namespace {

double MadVariance(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  const double med = *mid;
  for (double& x : v) x = std::abs(x - med);
  std::nth_element(v.begin(), mid, v.end());
  return (1.4826 * *mid) * (1.4826 * *mid);
}

}  // namespace

LidarSpread MeasureLidarSpread(const std::vector<double>& residuals,
                               const std::vector<Vec3>& plane_points, double cell) {
  LidarSpread out;
  out.residuals = static_cast<int>(residuals.size());
  if (residuals.empty()) return out;
  std::map<std::array<int64_t, 3>, std::vector<double>> groups;
  for (size_t i = 0; i < residuals.size(); ++i) {
    const Vec3 c = (plane_points[i] / cell).array().floor();
    groups[{static_cast<int64_t>(c.x()), static_cast<int64_t>(c.y()), static_cast<int64_t>(c.z())}]
        .push_back(residuals[i]);
  }
  std::vector<double> deviations, means;
  double sum_n2 = 0.0, sum_inv_n = 0.0;
  int in_pairs = 0, pair_groups = 0;
  for (const auto& [key, e] : groups) {
    const double n = static_cast<double>(e.size());
    double mean = 0.0;
    for (const double x : e) mean += x / n;
    means.push_back(mean);
    sum_n2 += n * n;
    sum_inv_n += 1.0 / n;
    if (e.size() < 2) continue;
    for (const double x : e) deviations.push_back(x - mean);
    in_pairs += static_cast<int>(e.size());
    ++pair_groups;
  }
  out.groups = static_cast<int>(groups.size());
  out.mean_group_size = sum_n2 / out.residuals;
  if (in_pairs > pair_groups) {
    // Deviations from a group's own mean have variance σ_p²·(n_j − 1)/n_j.
    out.point_variance = MadVariance(deviations) * in_pairs / (in_pairs - pair_groups);
  }
  const double between = MadVariance(means);
  out.common_variance =
      std::max(0.0, between - out.point_variance * sum_inv_n / static_cast<double>(out.groups));
  return out;
}

double AdaptiveNoiseScales::Smooth(double current, double estimate, bool first) const {
  if (!std::isfinite(estimate) || estimate <= 0.0) return current;
  const double clamped = std::clamp(estimate, options_.min_scale, options_.max_scale);
  if (first) return clamped;
  const double a = options_.smoothing;
  return std::exp((1.0 - a) * std::log(current) + a * std::log(clamped));
}

std::optional<Mat6> AdaptiveNoiseScales::Compute(SlidingWindow* window, StateId pose,
                                                 double lidar_estimate,
                                                 const std::vector<ceres::ResidualBlockId>& lidar,
                                                 const std::vector<ceres::ResidualBlockId>& accel,
                                                 const std::vector<ceres::ResidualBlockId>& gyro,
                                                 ceres::ResidualBlockId prior, const SE3& T_mr,
                                                 const Mat6& tangent_from_body) {
  std::vector<ScaledGroup> groups = {{lidar, lidar_}, {accel, accel_}, {gyro, gyro_}};
  const std::optional<GroupScaledCovariance> c =
      GroupScaledPoseCovariance(*window, pose, groups, prior, prior_, T_mr, tangent_from_body);
  if (!c) return std::nullopt;

  ceres::Problem* problem = &window->problem();
  const double s_lidar =
      std::isnan(lidar_estimate) ? RobustResidualVariance(problem, lidar) : lidar_estimate;
  const auto vce = [&](const std::vector<ceres::ResidualBlockId>& blocks, double trace,
                       double current) {
    const GroupChiSquare x = EvaluateGroupChiSquare(problem, blocks);
    const double redundancy = x.n - trace;
    return x.n > 0 && redundancy > 0.5 ? x.chi2 / redundancy : current;
  };
  const double s_accel = vce(accel, c->trace_share[1], accel_);
  const double s_gyro = vce(gyro, c->trace_share[2], gyro_);
  // (2): how far the rescaled groups moved the newest pose's covariance, in its own metric.
  const Eigen::LDLT<Mat6> ldlt(c->unscaled);
  const double s_prior = ldlt.solve(c->scaled).trace() / 6.0;

  lidar_ = Smooth(lidar_, s_lidar, first_);
  accel_ = Smooth(accel_, s_accel, first_);
  gyro_ = Smooth(gyro_, s_gyro, first_);
  prior_ = Smooth(prior_, s_prior, first_);
  first_ = false;
  return c->scaled;
}

double LidarVarianceFactor(const std::vector<double>& residuals, const std::vector<double>& sigmas,
                           const std::vector<Vec3>& plane_points, double neff) {
  if (sigmas.size() != residuals.size() || plane_points.size() != residuals.size()) {
    throw std::invalid_argument("LidarVarianceFactor: one σ and one plane point per residual");
  }
  std::vector<double> whitened(residuals.size());
  for (size_t i = 0; i < residuals.size(); ++i) whitened[i] = residuals[i] / sigmas[i];
  return neff * MeasureLidarSpread(whitened, plane_points, kLidarPlaneCell).effective_variance();
}

}  // namespace ctlio::lio
