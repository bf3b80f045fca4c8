// Per-axis motion model of the 1D study, evaluated through the project's GP module (SPEC §2) and
// cached per time step: a trajectory has only a handful of distinct steps (one per sensor-rate
// combination), so Φ, Q and their factorisations are computed once per step, not per node.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <deque>

#include "ctlio/study/simulation.h"

namespace ctlio::study {

struct DiscreteMotion {
  int64_t dt_ns = 0;
  Eigen::Matrix3d transition;       // Φ(Δt)
  Eigen::Matrix3d covariance;       // Q(Δt)
  Eigen::Matrix3d sqrt_covariance;  // L, L Lᵀ = Q
};

class MotionModelCache {
 public:
  explicit MotionModelCache(const PriorConfig& prior) : prior_(prior) {}
  const DiscreteMotion& Get(int64_t dt_ns);

 private:
  PriorConfig prior_;
  std::deque<DiscreteMotion> entries_;  // stable references
};

}  // namespace ctlio::study
