// Registration of one scan's keypoints against the voxel map (SPEC §4), the one loop every LIO
// pipeline (and any user of the window) runs:
//
//   for each round (≤ max_iterations):
//     associate  every keypoint, placed in the map by the current estimate, with a plane of the
//                map (PlaneAssociator) and give it a point-to-plane residual in the window:
//                a keypoint with a residual from an earlier round keeps its block with the new
//                plane written into it (LidarTerm::UpdateResidual), one that lost its plane
//                loses its block, a new one gets a block (LidarTerm::AddResidual) — the window
//                is that of removing all and adding them again up to the order of its blocks,
//                without Ceres' cost of removing and adding ~10³ blocks per round (a batched
//                term instead replaces its few per-interval blocks each round,
//                LidarTerm::SetBatchResiduals);
//                fewer than min_associations: degenerate scan, the lidar term is dropped;
//     solve      the window (solver_iterations Levenberg–Marquardt steps);
//     converged? the newest pose moved less than convergence_translation/_rotation.
//
// Where a keypoint lands in the map and which factor it gets depend on the state
// parametrisation; a LidarTerm supplies both (the GP knots' ContinuousPointToPlane, the
// navigation states' deskewed PointToPlaneWorld). The residuals of the last round stay in the
// window, so marginalisation keeps their information.
#pragma once

#include <ceres/loss_function.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"
#include "ctlio/solvers/lio/voxel_map.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// The keypoints of one scan as a measurement of the window's states.
class LidarTerm {
 public:
  virtual ~LidarTerm() = default;
  virtual size_t num_keypoints() const = 0;
  // Called before each association round: the estimate may have changed since the last one.
  virtual void BeginRound() {}
  // Keypoint i at the current estimate: q, the point in the frame its factor transforms, and
  // p_map, where that puts it in the map.
  virtual void Locate(size_t i, Vec3* q, Vec3* p_map) = 0;
  // Adds keypoint i's residual on the associated plane (weight already whitened) to the window.
  virtual ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& association,
                                             ceres::LossFunction* loss, SlidingWindow* window) = 0;
  // Keypoint i, whose residual AddResidual added in an earlier round of this registration and
  // which is still in the window, is associated again: its residual measures `association` from
  // now on (the cost function's set_association; between solves only). The residual block, its
  // loss and its place in the window stay.
  virtual void UpdateResidual(size_t i, const PlaneAssociation& association) = 0;
  // The pose whose change between rounds decides convergence (the newest state's).
  virtual SE3 NewestPose() const = 0;

  // Batched residuals (LidarFrontendOptions::residual_blocks "interval"): when true, the
  // registration gives each round's associations to SetBatchResiduals instead of AddResidual /
  // UpdateResidual per keypoint.
  virtual bool batched() const { return false; }
  // Replaces the residuals of the previous round (if any) by those of this round: keypoint i with
  // associated[i] != 0 measures planes[i] (weight already whitened) with the robust loss `loss`
  // (nullable) applied per keypoint. No associated keypoint: the lidar residuals are removed.
  // Writes the residual blocks now in the window into *blocks. Only called when batched().
  virtual void SetBatchResiduals(const std::vector<uint8_t>& associated,
                                 const std::vector<PlaneAssociation>& planes,
                                 const std::shared_ptr<const ceres::LossFunction>& loss,
                                 SlidingWindow* window,
                                 std::vector<ceres::ResidualBlockId>* blocks);
};

struct RegistrationSummary {
  int rounds = 0;             // association rounds run
  int solver_iterations = 0;  // Levenberg–Marquardt iterations, all rounds
  int associations = 0;       // residuals added in the last round
  double initial_cost = 0.0;  // Ceres cost at the start of the first round
  double final_cost = 0.0;    // Ceres cost after the last round
  bool converged = false;     // stopped because the newest pose moved less than the thresholds
  bool degenerate = false;    // too few associations: the lidar term was dropped
  double ms_associate = 0.0;  // wall time of the association, all rounds
  double ms_solve = 0.0;      // wall time of the solves, all rounds
  // The last round's residuals (in the window): one per keypoint, in keypoint order, or with a
  // batched term one per knot interval.
  std::vector<ceres::ResidualBlockId> lidar_blocks;
  // The last round's planes per keypoint (weight not whitened) and whether it has one (empty if
  // degenerate): what the residuals measure, e.g. for their spread (adaptive_covariance.h).
  std::vector<PlaneAssociation> planes;
  std::vector<uint8_t> associated;
  // Each keypoint's σ in the last round, the one its residual was whitened by (PointNoiseSigma;
  // 0 where it has no plane).
  std::vector<double> noise_sigma;
};

// The robust loss of the point-to-plane residuals (cauchy/huber/none, SPEC §4): the residuals
// are whitened by point_noise_sigma, so the scale, given in metres, is whitened too. nullptr for
// "none".
std::unique_ptr<ceres::LossFunction> MakeLidarLoss(const LidarFrontendOptions& options);

// The σ that whitens the residual of a keypoint at q_robot (robot frame) against a plane of
// thickness σ3 = plane_thickness: √(point_noise_sigma² + (point_noise_angle·|q_robot|)² +
// (plane_thickness_noise·σ3)²); point_noise_sigma when the angle and the factor are 0.
double PointNoiseSigma(const LidarFrontendOptions& options, const Vec3& q_robot,
                       double plane_thickness = 0.0);

class ScanRegistration {
 public:
  ScanRegistration(const LidarFrontendOptions& options, int min_associations);

  // max_rounds > 0 replaces options().max_iterations for this scan (the budget of a scan without
  // IMU measurements, LidarFrontendOptions::max_iterations_without_imu).
  RegistrationSummary Register(const VoxelMap& map, LidarTerm* term, SlidingWindow* window,
                               int max_rounds = 0) const;

  const LidarFrontendOptions& options() const { return options_; }

 private:
  LidarFrontendOptions options_;
  int min_associations_;
};

}  // namespace ctlio::lio
