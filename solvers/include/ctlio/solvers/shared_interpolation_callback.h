// The Ceres mechanism for work shared between residual blocks (ceres::EvaluationCallback): before
// every evaluation Ceres copies the new point into the parameter blocks and calls
// PrepareForEvaluation, and this callback interpolates each registered firing once
// (SharedPoseInterpolation::Prepare) for all the point-to-plane residuals that share it.
//
// Firings are held weakly: one whose residuals have all been removed (marginalisation) expires
// and is dropped here. Only active firings (some residual reads them) are prepared, and each only
// when the knots moved since its last preparation.
#pragma once

#include <ceres/evaluation_callback.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "ctlio/factors/lidar/shared_pose_interpolation.h"

namespace ctlio {

class SharedInterpolationCallback final : public ceres::EvaluationCallback {
 public:
  void Add(const std::shared_ptr<SharedPoseInterpolation>& firing) { firings_.push_back(firing); }

  // The flags are not needed: Prepare always forms the Jacobians too, and skips a firing whose
  // knots have not moved since it was last prepared.
  void PrepareForEvaluation(bool /*evaluate_jacobians*/, bool /*new_evaluation_point*/) override {
    firings_.erase(
        std::remove_if(firings_.begin(), firings_.end(), [](const auto& f) { return f.expired(); }),
        firings_.end());
    for (const auto& weak : firings_) {
      const std::shared_ptr<SharedPoseInterpolation> f = weak.lock();
      if (f->active()) f->Prepare();
    }
  }

  // Live firings (those some residual or their owner still holds).
  size_t size() const {
    return static_cast<size_t>(std::count_if(firings_.begin(), firings_.end(),
                                             [](const auto& f) { return !f.expired(); }));
  }

 private:
  std::vector<std::weak_ptr<SharedPoseInterpolation>> firings_;
};

}  // namespace ctlio
