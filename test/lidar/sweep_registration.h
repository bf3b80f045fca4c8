// Registration of one sweep against a map with the odometry's own components (SPEC §4): a
// SlidingWindow, the ScanRegistration loop (associate → solve → converged?) and, for the
// continuous-time fit, the pipeline's ContinuousLidarTerm on two GP knots tied by the Singer
// prior (one residual block per keypoint or one for the interval, as options.residual_blocks). A
// rigid fit (one pose, PointToPlane) gives the no-motion baseline. Shared by the real Newer College
// sweep test and the lidar benchmark.
#pragma once

#include <vector>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/continuous_lidar_term.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio::sweep {

// The odometry's window solver: Levenberg–Marquardt, dense normal Cholesky (38 or 6 tangent
// parameters), solver_iterations steps per round.
inline SlidingWindowOptions SweepWindowOptions(const LidarFrontendOptions& options) {
  SlidingWindowOptions o;
  o.solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  o.solver.max_num_iterations = options.solver_iterations;
  o.threads = options.threads;  // as window.threads: the interpolations and lidar rows
  return o;
}

// One pose T_rm for all keypoints (their times ignored).
class RigidLidarTerm final : public LidarTerm {
 public:
  RigidLidarTerm(StateId pose, const std::vector<TimedPoint>& keypoints, const SlidingWindow& w)
      : pose_(pose), block_(w.State(pose)), keypoints_(keypoints) {}
  size_t num_keypoints() const override { return keypoints_.size(); }
  void BeginRound() override { T_mr_ = PoseManifold::Pose(block_).Inverse(); }
  void Locate(size_t i, Vec3* q, Vec3* p_map) override {
    *q = keypoints_[i].point;
    *p_map = T_mr_ * *q;
  }
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& a, ceres::LossFunction* loss,
                                     SlidingWindow* window) override {
    if (costs_.empty()) costs_.resize(keypoints_.size(), nullptr);
    costs_[i] = new PointToPlane(a);
    return window->AddResidualBlock(costs_[i], loss, {pose_});
  }
  void UpdateResidual(size_t i, const PlaneAssociation& a) override {
    costs_[i]->set_association(a);
  }
  SE3 NewestPose() const override { return PoseManifold::Pose(block_); }

 private:
  StateId pose_;
  const double* block_;
  const std::vector<TimedPoint>& keypoints_;
  SE3 T_mr_;
  std::vector<PointToPlane*> costs_;  // per keypoint, owned by the window
};

inline RegistrationSummary RegisterRigid(const VoxelMap& map, const LidarFrontendOptions& options,
                                         const std::vector<TimedPoint>& keypoints, SE3* T_rm) {
  SlidingWindow window(SweepWindowOptions(options));
  window.AddPoseState(0, *T_rm);
  RigidLidarTerm term(0, keypoints, window);
  const RegistrationSummary summary =
      ScanRegistration(options, OdometryConfig().min_associations).Register(map, &term, &window);
  *T_rm = window.Pose(0);
  return summary;
}

// Refines knots k (at t_k) and k1 (at t_k1) from the caller's initial values.
inline RegistrationSummary RegisterContinuous(const VoxelMap& map,
                                              const LidarFrontendOptions& options,
                                              const gp::SingerModel<6>& model,
                                              const std::vector<TimedPoint>& keypoints, double t_k,
                                              double t_k1, gp::KnotState* k, gp::KnotState* k1) {
  SlidingWindow window(SweepWindowOptions(options));
  const KnotKeys a = KnotKeys::ForKnot(0), b = KnotKeys::ForKnot(1);
  for (const auto& [keys, x] : {std::make_pair(a, k), std::make_pair(b, k1)}) {
    window.AddPoseState(keys.pose, x->pose);
    window.AddVectorState(keys.velocity, x->velocity);
    window.AddVectorState(keys.acceleration, x->acceleration);
  }
  window.AddResidualBlock(new gp::SingerPrior(model, t_k1 - t_k), nullptr, KnotPair(a, b));
  ContinuousLidarTerm term(model, t_k, t_k1, a, b, keypoints, &window);
  term.set_residual_blocks(options.residual_blocks);  // as the odometry builds it
  const RegistrationSummary summary =
      ScanRegistration(options, OdometryConfig().min_associations).Register(map, &term, &window);
  *k = gp::ReadKnotState(window.State(a.pose), window.State(a.velocity),
                         window.State(a.acceleration));
  *k1 = gp::ReadKnotState(window.State(b.pose), window.State(b.velocity),
                          window.State(b.acceleration));
  return summary;
}

}  // namespace ctlio::lio::sweep
