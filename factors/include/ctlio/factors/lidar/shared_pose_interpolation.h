// The interpolated pose T_rm(τ) and its Jacobians onto both knots (gp::GpInterpolator::Pose,
// SPEC §2), shared by all residuals whose points were measured at the same time τ (the points of
// one lidar firing). SPEC §4 keeps one residual per point, each with its own robust loss; only
// the interpolation, the dominant cost of a scan, is shared.
//
// Two ways to obtain it, with identical values:
//   - prepared: Prepare() reads the six knot blocks it was bound to and stores T(τ), J_k, J_k+1.
//     A ceres::EvaluationCallback calls it once per evaluation point, before Ceres evaluates the
//     cost functions (solvers/shared_interpolation_callback.h; the SlidingWindow owns one and also
//     runs it before it linearises for marginalisation);
//   - computed: Pose() called with parameter values other than the prepared ones (or before any
//     Prepare) interpolates itself. This is what ceres::GradientChecker, or any caller that
//     evaluates a cost function outside Ceres' own evaluation loop, gets.
// Pose() only reads shared state, so concurrent Evaluate calls are safe; Prepare() must not run
// concurrently with them (Ceres calls the callback before it starts evaluating).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"

namespace ctlio {

class SharedPoseInterpolation {
 public:
  // The knot blocks in the order pose_k (7), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1.
  using KnotBlocks = std::array<const double*, 6>;

  // `knots` are the parameter blocks Prepare() reads; all null for an interpolation that is only
  // ever computed on demand (a cost function used outside a window).
  explicit SharedPoseInterpolation(std::shared_ptr<const gp::GpInterpolator> interpolator,
                                   const KnotBlocks& knots = {})
      : interpolator_(std::move(interpolator)), knots_(knots) {}

  // Interpolation (with both Jacobians: after a trust-region step is accepted Ceres asks for the
  // Jacobians at the point whose cost it just evaluated) at the values now in the knot blocks;
  // nothing to do if it was prepared at exactly these values already (e.g. the solve ended at
  // the point the marginalisation then linearises at).
  void Prepare() {
    if (knots_[0] == nullptr || PreparedAt(knots_.data())) return;
    for (int b = 0, o = 0; b < 6; o += kSizes[b], ++b) {
      std::memcpy(values_.data() + o, knots_[b], kSizes[b] * sizeof(double));
    }
    interpolator_->Pose(gp::ReadKnotState(knots_[0], knots_[1], knots_[2]),
                        gp::ReadKnotState(knots_[3], knots_[4], knots_[5]), &T_, &J_k_, &J_k1_);
    prepared_ = true;
  }
  bool prepared() const { return prepared_; }
  // T(τ) of the last Prepare().
  const SE3& pose() const { return T_; }

  // Whether any residual reads this interpolation now (an evaluation callback skips it if not).
  bool active() const { return active_; }
  void set_active(bool active) { active_ = active; }

  // T(τ) and the Jacobians (each may be null) at `parameters` (the six knot blocks' values, in
  // the order above): the prepared result if it was prepared at exactly these values, otherwise
  // interpolated here.
  void Pose(double const* const* parameters, SE3* T, gp::PoseJacobian* J_k,
            gp::PoseJacobian* J_k1) const {
    if (PreparedAt(parameters)) {
      *T = T_;
      if (J_k != nullptr) *J_k = J_k_;
      if (J_k1 != nullptr) *J_k1 = J_k1_;
      return;
    }
    computed_.fetch_add(1, std::memory_order_relaxed);
    interpolator_->Pose(gp::ReadKnotState(parameters[0], parameters[1], parameters[2]),
                        gp::ReadKnotState(parameters[3], parameters[4], parameters[5]), T, J_k,
                        J_k1);
  }

  const gp::GpInterpolator& interpolator() const { return *interpolator_; }
  // How often Pose() had to interpolate itself (0 inside a window's solve: the sharing works).
  int64_t num_computed() const { return computed_.load(std::memory_order_relaxed); }

 private:
  static constexpr int kSizes[6] = {7, 6, 6, 7, 6, 6};
  static constexpr int kValues = 38;

  bool PreparedAt(double const* const* parameters) const {
    if (!prepared_) return false;
    for (int b = 0, o = 0; b < 6; o += kSizes[b], ++b) {
      if (std::memcmp(values_.data() + o, parameters[b], kSizes[b] * sizeof(double)) != 0) {
        return false;
      }
    }
    return true;
  }

  std::shared_ptr<const gp::GpInterpolator> interpolator_;
  KnotBlocks knots_;
  bool prepared_ = false;
  bool active_ = true;
  std::array<double, kValues> values_{};
  SE3 T_;
  gp::PoseJacobian J_k_, J_k1_;
  mutable std::atomic<int64_t> computed_{0};
};

}  // namespace ctlio
