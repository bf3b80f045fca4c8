// The keypoints of a scan as measurements of the GP trajectory over the knots that span the sweep
// (SPEC §4; two knots, or more with window.knots_per_scan): one ContinuousPointToPlane per
// associated keypoint at its own time τ, on the interval between the two knots around τ (a
// point at an interior knot's time belongs to the interval that ends there). The points of one
// firing (same τ) share one SharedPoseInterpolation (its gp::GpInterpolator's Λ, Ω depend on the
// times only: built once per scan), which the window's evaluation callback fills once per
// evaluation (SlidingWindow::shared_interpolations()) and the association reads at the current
// estimate. With the extrinsic estimated (online calibration, kExtrinsicKey in the window), every
// keypoint is a ContinuousPointToPlaneExtrinsic of its lidar-frame point instead, and the
// association places it with the extrinsic's current estimate.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/lidar/continuous_point_to_plane_batch.h"
#include "ctlio/factors/lidar/shared_pose_interpolation.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

// A knot of the window and its time.
struct TimedKnot {
  double t = 0.0;
  KnotKeys keys;
};

class ContinuousLidarTerm final : public LidarTerm {
 public:
  // `knots` (at least two, times strictly increasing) are states of `window`; keypoints in the
  // robot frame with times in [front.t, back.t] (LioOdometry drops or clamps the points outside
  // before they get here; the clamp inside only absorbs rounding, never extrapolates). The
  // keypoints are referenced, not copied. Registers its firings with the window's callback.
  ContinuousLidarTerm(const gp::SingerModel<6>& model, const std::vector<TimedKnot>& knots,
                      const std::vector<TimedPoint>& keypoints, SlidingWindow* window);
  // With the extrinsic T_rl estimated: the window's kExtrinsicKey block; `T_robot_lidar` is the
  // extrinsic the keypoints were moved into the robot frame with (PreparedScan::T_robot_lidar).
  ContinuousLidarTerm(const gp::SingerModel<6>& model, const std::vector<TimedKnot>& knots,
                      const std::vector<TimedPoint>& keypoints, const SE3& T_robot_lidar,
                      SlidingWindow* window);
  // Between two knots k (at t_k) and k1 (at t_k1 > t_k), without and with the extrinsic.
  ContinuousLidarTerm(const gp::SingerModel<6>& model, double t_k, double t_k1, const KnotKeys& k,
                      const KnotKeys& k1, const std::vector<TimedPoint>& keypoints,
                      SlidingWindow* window)
      : ContinuousLidarTerm(model, {{t_k, k}, {t_k1, k1}}, keypoints, window) {}
  ContinuousLidarTerm(const gp::SingerModel<6>& model, double t_k, double t_k1, const KnotKeys& k,
                      const KnotKeys& k1, const std::vector<TimedPoint>& keypoints,
                      const SE3& T_robot_lidar, SlidingWindow* window)
      : ContinuousLidarTerm(model, {{t_k, k}, {t_k1, k1}}, keypoints, T_robot_lidar, window) {}

  size_t num_keypoints() const override { return keypoints_.size(); }
  void BeginRound() override;
  void Locate(size_t i, Vec3* q, Vec3* p_map) override;
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& association,
                                     ceres::LossFunction* loss, SlidingWindow* window) override;
  void UpdateResidual(size_t i, const PlaneAssociation& association) override;
  SE3 NewestPose() const override;  // T_rm of the last knot

  // As LidarFrontendOptions::residual_blocks: "point", one block per keypoint; "interval" and
  // "square_root" batch the keypoints of each knot interval into one ContinuousPointToPlaneBatch
  // of point rows or in square-root form (that only where it has fewer rows: more than W + 1 = 37
  // points). Also with the extrinsic estimated (the batch's extrinsic form, a seventh block T_rl):
  // per keypoint, the extrinsic's blocks cost a calibrating scan ~2.5x the CPU of the same scan
  // without calibration, most of it Ceres' per-block work in the solve and the marginalisation
  // (docs/experiments/calibration.md, "CPU per calibrating scan"). The batch matches the
  // per-point factors' cost, gradient and Hessian up to rounding; in a calibrating window the
  // first marginal prior is nearly singular along pose–extrinsic directions just above the rank
  // threshold, and its residual r0 there amplifies rounding (Sᵀr0 equal to 1e-11, ‖r0‖ 1.109 vs
  // 1.160), so the two differ by up to ~1 cm in a sparse run's first second (ATE 2.06 cm per
  // keypoint, 2.02–2.11 batched: lio.LioPipeline.IntervalResidualBlocksGiveThePerPointEstimates)
  // and within noise over 20 s (docs/experiments/calibration.md); "point" keeps the per-keypoint
  // blocks.
  void set_residual_blocks(const std::string& residual_blocks) {
    batched_ = residual_blocks == "interval" || residual_blocks == "square_root";
    batch_form_ = residual_blocks == "square_root" ? ContinuousPointToPlaneBatch::Form::kSquareRoot
                                                   : ContinuousPointToPlaneBatch::Form::kPointRows;
  }
  bool batched() const override { return batched_; }
  void SetBatchResiduals(const std::vector<uint8_t>& associated,
                         const std::vector<PlaneAssociation>& planes,
                         const std::shared_ptr<const ceres::LossFunction>& loss,
                         SlidingWindow* window,
                         std::vector<ceres::ResidualBlockId>* blocks) override;

  int num_firings() const { return static_cast<int>(firings_.size()); }
  // The interval (0 = between the first two knots) keypoint i is a measurement on.
  int interval_of(size_t i) const { return interval_[static_cast<size_t>(firing_[i])]; }

 private:
  const std::vector<TimedPoint>& keypoints_;
  // Per interval between consecutive knots: pose, ϖ, ϖ̇ of its first knot, then of its second.
  std::vector<std::vector<StateId>> states_;
  std::vector<SharedPoseInterpolation::KnotBlocks> blocks_;
  const double* newest_pose_ = nullptr;  // the last knot's T_rm block
  std::vector<int> firing_;              // keypoint → firing
  std::vector<int> interval_;            // firing → interval
  std::vector<std::shared_ptr<SharedPoseInterpolation>> firings_;
  // Per firing, this round: the map pose at the current estimate (for the association).
  std::vector<SE3> T_mr_;
  std::vector<bool> located_;
  // Per keypoint: the cost function AddResidual gave it (ContinuousPointToPlane, or
  // ContinuousPointToPlaneExtrinsic with calibration), owned by the window; read by
  // UpdateResidual only while its block is in the window.
  std::vector<ceres::CostFunction*> costs_;
  // Online calibration only (else empty / null): the keypoints in the lidar frame, the extrinsic
  // block and its value this round.
  std::vector<Vec3> points_lidar_;
  const double* extrinsic_ = nullptr;
  SE3 T_rl_;
  bool batched_ = false;
  ContinuousPointToPlaneBatch::Form batch_form_ = ContinuousPointToPlaneBatch::Form::kPointRows;
};

}  // namespace ctlio::lio
