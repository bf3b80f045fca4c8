#include "ctlio/solvers/lio/registration.h"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::lio {

namespace {

// The residuals are whitened by σ (point_noise_sigma), so the loss scale, given in metres, is
// whitened too.
std::unique_ptr<ceres::LossFunction> MakeLoss(const LidarFrontendOptions& o) {
  const double scale = o.loss_scale / o.point_noise_sigma;
  if (o.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(scale);
  if (o.loss == "huber") return std::make_unique<ceres::HuberLoss>(scale);
  return nullptr;
}

ceres::Problem::Options ProblemOptions() {
  ceres::Problem::Options p;
  // The loss and the manifold are shared by all residuals and owned here; the cost functions
  // are owned by the problem.
  p.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  p.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  p.enable_fast_removal = false;
  return p;
}

ceres::Solver::Options SolverOptions(const LidarFrontendOptions& o) {
  ceres::Solver::Options s;
  s.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // 38 (or 7) parameters and thousands of residuals: the normal equations are tiny and dense.
  s.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  s.max_num_iterations = o.solver_iterations;
  s.num_threads = 1;
  s.logging_type = ceres::SILENT;
  s.minimizer_progress_to_stdout = false;
  return s;
}

// Rotation angle and translation of T_a·T_b⁻¹.
void Difference(const SE3& a, const SE3& b, double* translation, double* rotation) {
  const SE3 d = a * b.Inverse();
  *translation = d.translation().norm();
  *rotation = so3::Log(d.rotation()).norm();
}

}  // namespace

SweepRegistration::SweepRegistration(const LidarFrontendOptions& options,
                                     const gp::SingerModel<6>& model)
    : options_(options), model_(model) {
  options_.Validate();
}

RegistrationSummary SweepRegistration::Register(const VoxelMap& map,
                                                const std::vector<TimedPoint>& keypoints,
                                                double t_k, double t_k1, gp::KnotState* k,
                                                gp::KnotState* k1) const {
  if (!(t_k1 > t_k)) throw std::invalid_argument("SweepRegistration::Register: need t_k < t_k1");
  RegistrationSummary summary;
  summary.num_points = static_cast<int>(keypoints.size());

  // One interpolator per distinct point time (a spinning lidar fires a column of beams at
  // once, so many points share a time). Built once: the knot times do not change.
  std::vector<std::shared_ptr<const gp::GpInterpolator>> interpolators(keypoints.size());
  {
    std::map<double, std::shared_ptr<const gp::GpInterpolator>> by_time;
    for (size_t i = 0; i < keypoints.size(); ++i) {
      const double tau = keypoints[i].time;
      if (!(tau >= t_k && tau <= t_k1)) {
        std::ostringstream s;
        s << "SweepRegistration::Register: keypoint " << i << " at t = " << tau
          << " outside the knots' interval [" << t_k << ", " << t_k1 << "]";
        throw std::invalid_argument(s.str());
      }
      auto& slot = by_time[tau];
      if (!slot) slot = std::make_shared<const gp::GpInterpolator>(model_, t_k, t_k1, tau);
      interpolators[i] = slot;
    }
  }

  double pose_k[7], w_k[6], a_k[6], pose_k1[7], w_k1[6], a_k1[6];
  auto store = [&]() {
    PoseManifold::Store(k->pose, pose_k);
    PoseManifold::Store(k1->pose, pose_k1);
    Eigen::Map<Vec6>{w_k} = k->velocity;
    Eigen::Map<Vec6>{a_k} = k->acceleration;
    Eigen::Map<Vec6>{w_k1} = k1->velocity;
    Eigen::Map<Vec6>{a_k1} = k1->acceleration;
  };
  store();

  const std::unique_ptr<ceres::LossFunction> loss = MakeLoss(options_);
  PoseManifold pose_manifold;
  const ceres::Solver::Options solver_options = SolverOptions(options_);
  PlaneAssociator associator(map, options_);

  for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
    const gp::KnotState start = *k, end = *k1;
    ceres::Problem problem(ProblemOptions());
    double* blocks[6] = {pose_k, w_k, a_k, pose_k1, w_k1, a_k1};
    problem.AddParameterBlock(pose_k, 7, &pose_manifold);
    problem.AddParameterBlock(pose_k1, 7, &pose_manifold);
    problem.AddResidualBlock(new gp::SingerPrior(model_, t_k1 - t_k), nullptr, blocks, 6);

    int associated = 0;
    PlaneAssociation association;
    for (size_t i = 0; i < keypoints.size(); ++i) {
      SE3 T_rm_tau;
      interpolators[i]->Pose(start, end, &T_rm_tau, nullptr, nullptr);
      const Vec3 p_map = T_rm_tau.Inverse() * keypoints[i].point;
      if (!associator.Associate(keypoints[i].point, p_map, &association)) continue;
      association.weight /= options_.point_noise_sigma;
      problem.AddResidualBlock(new ContinuousPointToPlane(interpolators[i], association),
                               loss.get(), blocks, 6);
      ++associated;
    }
    summary.num_associations = associated;
    summary.iterations = iteration + 1;

    ceres::Solver::Summary solver_summary;
    ceres::Solve(solver_options, &problem, &solver_summary);
    if (iteration == 0) summary.initial_cost = solver_summary.initial_cost;
    summary.final_cost = solver_summary.final_cost;

    *k = gp::ReadKnotState(pose_k, w_k, a_k);
    *k1 = gp::ReadKnotState(pose_k1, w_k1, a_k1);
    double dt0, dr0, dt1, dr1;
    Difference(k->pose, start.pose, &dt0, &dr0);
    Difference(k1->pose, end.pose, &dt1, &dr1);
    if (std::max(dt0, dt1) < options_.convergence_translation &&
        std::max(dr0, dr1) < options_.convergence_rotation) {
      summary.converged = true;
      break;
    }
  }
  return summary;
}

RegistrationSummary SweepRegistration::RegisterRigid(const VoxelMap& map,
                                                     const std::vector<TimedPoint>& keypoints,
                                                     SE3* T_rm) const {
  RegistrationSummary summary;
  summary.num_points = static_cast<int>(keypoints.size());
  double pose[7];
  PoseManifold::Store(*T_rm, pose);
  const std::unique_ptr<ceres::LossFunction> loss = MakeLoss(options_);
  PoseManifold pose_manifold;
  const ceres::Solver::Options solver_options = SolverOptions(options_);
  PlaneAssociator associator(map, options_);
  for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
    const SE3 before = *T_rm;
    const SE3 T_mr = before.Inverse();
    ceres::Problem problem(ProblemOptions());
    problem.AddParameterBlock(pose, 7, &pose_manifold);
    int associated = 0;
    PlaneAssociation association;
    for (const TimedPoint& kp : keypoints) {
      if (!associator.Associate(kp.point, T_mr * kp.point, &association)) continue;
      association.weight /= options_.point_noise_sigma;
      problem.AddResidualBlock(new PointToPlane(association), loss.get(), pose);
      ++associated;
    }
    summary.num_associations = associated;
    summary.iterations = iteration + 1;
    if (associated == 0) break;
    ceres::Solver::Summary solver_summary;
    ceres::Solve(solver_options, &problem, &solver_summary);
    if (iteration == 0) summary.initial_cost = solver_summary.initial_cost;
    summary.final_cost = solver_summary.final_cost;
    *T_rm = PoseManifold::Pose(pose);
    double dt, dr;
    Difference(*T_rm, before, &dt, &dr);
    if (dt < options_.convergence_translation && dr < options_.convergence_rotation) {
      summary.converged = true;
      break;
    }
  }
  return summary;
}

}  // namespace ctlio::lio
