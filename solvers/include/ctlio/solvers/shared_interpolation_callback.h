// The Ceres mechanism for work shared between residual blocks (ceres::EvaluationCallback): before
// every evaluation Ceres copies the new point into the parameter blocks and calls
// PrepareForEvaluation, and this callback interpolates each registered interpolation once
// (gp::SharedInterpolation::Prepare: a lidar firing's pose for all the point-to-plane residuals
// that share it, an IMU sample's state for its gyro and accelerometer residuals). Interpolations
// on the same knot blocks also share one gp::SharedKnotInterval, the local variables γ_{k+1} of
// the interval and their Jacobians, formed once per evaluation point instead of once per
// interpolation.
//
// Interpolations are held weakly: one whose residuals have all been removed (marginalisation)
// expires and is dropped here. Only active ones (some residual reads them) are prepared, and each
// only when the knots moved since its last preparation.
#pragma once

#include <ceres/evaluation_callback.h>

#include <algorithm>
#include <map>
#include <memory>
#include <vector>

#include "ctlio/factors/gp/shared_interpolation.h"
#include "ctlio/factors/gp/shared_knot_interval.h"
#include "ctlio/solvers/parallel_for.h"

namespace ctlio {

class SharedInterpolationCallback final : public ceres::EvaluationCallback {
 public:
  // Registers `interpolation` and binds it to the shared interval of its knot blocks.
  void Add(const std::shared_ptr<gp::SharedInterpolation>& interpolation) {
    interpolations_.push_back(interpolation);
    const gp::KnotBlocks& knots = interpolation->knots();
    if (knots[0] == nullptr) return;
    std::weak_ptr<gp::SharedKnotInterval>& slot = intervals_[knots];
    std::shared_ptr<gp::SharedKnotInterval> interval = slot.lock();
    if (interval == nullptr) {
      interval = std::make_shared<gp::SharedKnotInterval>(knots);
      slot = interval;
    }
    interpolation->set_interval(std::move(interval));
  }

  // Threads for PrepareForEvaluation (the window sets SlidingWindowOptions::threads here): the
  // intervals are formed first, on the calling thread, then the interpolations, which only read
  // them and write their own results, in contiguous chunks. Same results for any count.
  void set_threads(int threads) { threads_ = std::max(threads, 1); }

  // The flags are not needed: Prepare always forms the Jacobians too, and skips an interpolation
  // whose knots have not moved since it was last prepared.
  void PrepareForEvaluation(bool /*evaluate_jacobians*/, bool /*new_evaluation_point*/) override {
    interpolations_.erase(std::remove_if(interpolations_.begin(), interpolations_.end(),
                                         [](const auto& f) { return f.expired(); }),
                          interpolations_.end());
    for (auto it = intervals_.begin(); it != intervals_.end();) {
      it = it->second.expired() ? intervals_.erase(it) : std::next(it);
    }
    active_.clear();
    for (const auto& weak : interpolations_) {
      std::shared_ptr<gp::SharedInterpolation> f = weak.lock();
      if (f->active()) active_.push_back(std::move(f));
    }
    // A few thousand interpolations per evaluation are worth a second thread; a handful not.
    const int threads = active_.size() >= 256 ? threads_ : 1;
    if (threads > 1) {
      for (const auto& [knots, weak] : intervals_) {
        if (const std::shared_ptr<gp::SharedKnotInterval> interval = weak.lock()) {
          interval->Prepare();
        }
      }
    }
    ParallelFor(threads, active_.size(), [&](size_t, size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) active_[i]->Prepare();
    });
    active_.clear();
  }

  // Live interpolations (those some residual or their owner still holds).
  size_t size() const {
    return static_cast<size_t>(std::count_if(interpolations_.begin(), interpolations_.end(),
                                             [](const auto& f) { return !f.expired(); }));
  }

 private:
  std::vector<std::weak_ptr<gp::SharedInterpolation>> interpolations_;
  // One interval per knot-block tuple, held by the interpolations on it.
  std::map<gp::KnotBlocks, std::weak_ptr<gp::SharedKnotInterval>> intervals_;
  std::vector<std::shared_ptr<gp::SharedInterpolation>> active_;  // this evaluation's, reused
  int threads_ = 1;
};

}  // namespace ctlio
