// An interpolation at one time τ between two knots, shared by all the residuals that read the
// state at τ, in one of two ways with identical values:
//   - prepared: Prepare() reads the six knot blocks it was bound to and interpolates (with the
//     Jacobians: after a trust-region step is accepted Ceres asks for them at the point whose cost
//     it just evaluated). A ceres::EvaluationCallback calls it once per evaluation point, before
//     Ceres evaluates the cost functions (solvers/shared_interpolation_callback.h);
//   - computed: a residual evaluated at parameter values other than the prepared ones (or before
//     any Prepare) interpolates itself. This is what ceres::GradientChecker, or any caller that
//     evaluates a cost function outside Ceres' own evaluation loop, gets.
// With a SharedKnotInterval (set_interval) a preparation also takes the interval's local
// variables, formed once for all the interpolations between the same knots.
// Reads of the prepared result are const and safe concurrently; Prepare() must not run
// concurrently with them (Ceres calls the callback before it starts evaluating).
//
// Derived: SharedPoseInterpolation (lidar firings, T(τ)), SharedStateInterpolation (IMU samples,
// T(τ), ϖ(τ), ϖ̇(τ)).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <utility>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/shared_knot_interval.h"

namespace ctlio::gp {

class SharedInterpolation {
 public:
  // `knots` are the parameter blocks Prepare() reads; all null for an interpolation that is only
  // ever computed on demand (a cost function used outside a window).
  explicit SharedInterpolation(const KnotBlocks& knots) : knots_(knots) {}
  virtual ~SharedInterpolation() = default;
  SharedInterpolation(const SharedInterpolation&) = delete;
  SharedInterpolation& operator=(const SharedInterpolation&) = delete;

  // Interpolates at the values now in the knot blocks; nothing to do if it was prepared at
  // exactly these values already (e.g. the solve ended at the point the marginalisation then
  // linearises at).
  void Prepare() {
    if (knots_[0] == nullptr || PreparedAt(knots_.data())) return;
    values_.Read(knots_.data());
    const LocalVariables* local = nullptr;
    if (interval_ != nullptr) {
      interval_->Prepare();
      local = interval_->At(values_);
    }
    Interpolate(values_, local);
    prepared_ = true;
  }
  bool prepared() const { return prepared_; }

  // Whether any residual reads this interpolation now (an evaluation callback skips it if not).
  bool active() const { return active_; }
  void set_active(bool active) { active_ = active; }

  const KnotBlocks& knots() const { return knots_; }
  // The interval of these knots (the same knot blocks), shared with other interpolations on it.
  void set_interval(std::shared_ptr<SharedKnotInterval> interval) {
    interval_ = std::move(interval);
  }

  // How often a read had to interpolate itself (0 inside a window's solve: the sharing works).
  int64_t num_computed() const { return computed_.load(std::memory_order_relaxed); }

 protected:
  // Interpolates at `values` (local: the interval's local variables at them, or null) into the
  // prepared result.
  virtual void Interpolate(const KnotValues& values, const LocalVariables* local) = 0;

  bool PreparedAt(double const* const* parameters) const {
    return prepared_ && values_.Equals(parameters);
  }
  void CountComputed() const { computed_.fetch_add(1, std::memory_order_relaxed); }
  // The interval's local variables if it still holds the values of the last preparation.
  const LocalVariables* IntervalLocal() const {
    return interval_ != nullptr ? interval_->At(values_) : nullptr;
  }
  // Drops the prepared result (a derived class whose request grew).
  void Invalidate() { prepared_ = false; }

 private:
  KnotBlocks knots_;
  std::shared_ptr<SharedKnotInterval> interval_;
  KnotValues values_;
  bool prepared_ = false;
  bool active_ = true;
  mutable std::atomic<int64_t> computed_{0};
};

}  // namespace ctlio::gp
