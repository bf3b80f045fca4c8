// Registration of one lidar sweep against the voxel map (SPEC §4): the trajectory over the
// sweep is two GP knots (t_k, t_k1) tied by the Singer/WNOJ prior (SPEC §2); every keypoint
// contributes one ContinuousPointToPlane residual at its own time. Associations are redone
// from the current estimate before each solve (at most max_iterations rounds of
// solver_iterations Levenberg–Marquardt steps), as in CT-ICP / the reference implementation.
// A rigid variant (one pose for the whole sweep, PointToPlane) gives the no-motion baseline.
//
// This is the building block the odometry calls per scan; it owns no state between sweeps.
#pragma once

#include <memory>
#include <vector>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"
#include "ctlio/solvers/lio/voxel_map.h"

namespace ctlio::lio {

struct RegistrationSummary {
  int iterations = 0;         // association rounds run
  int num_points = 0;         // keypoints offered
  int num_associations = 0;   // associated in the last round
  double initial_cost = 0.0;  // Ceres cost of the first round
  double final_cost = 0.0;    // Ceres cost after the last round
  bool converged = false;     // stopped because the knots moved less than the thresholds
};

class SweepRegistration {
 public:
  SweepRegistration(const LidarFrontendOptions& options, const gp::SingerModel<6>& model);

  // Refines the knots k (at t_k) and k1 (at t_k1) in place so that the keypoints (robot frame,
  // times in [t_k, t_k1]; throws std::invalid_argument otherwise), moved into the map frame by
  // T_mr(τ) = T_rm(τ)⁻¹, lie on the map's planes. The initial knots are the caller's prediction.
  RegistrationSummary Register(const VoxelMap& map, const std::vector<TimedPoint>& keypoints,
                               double t_k, double t_k1, gp::KnotState* k, gp::KnotState* k1) const;

  // One rigid pose T_rm for all keypoints (their times ignored).
  RegistrationSummary RegisterRigid(const VoxelMap& map, const std::vector<TimedPoint>& keypoints,
                                    SE3* T_rm) const;

  const LidarFrontendOptions& options() const { return options_; }
  const gp::SingerModel<6>& model() const { return model_; }

 private:
  LidarFrontendOptions options_;
  gp::SingerModel<6> model_;
};

}  // namespace ctlio::lio
