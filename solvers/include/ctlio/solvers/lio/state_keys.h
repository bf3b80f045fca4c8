// Named keys of the parameter blocks the LIO estimators keep in their SlidingWindow (SPEC §5):
// one struct per kind of state instead of id arithmetic at the call sites. The n-th state's
// blocks get the ids 8n + offset, so that the window's ascending-id order (which orders the
// marginal prior's states) follows time.
#pragma once

#include <cstdint>
#include <vector>

#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// C_mi, the gravity-aligned frame i → map frame m (a RotationManifold block, SPEC §3).
inline constexpr StateId kGravityKey = -1;
// T_rl = T_imu_lidar, lidar → robot frame (a PoseManifold block), with calibration.
// estimate_extrinsic only: a static state like C_mi, never marginalised (calibration_options.h).
inline constexpr StateId kExtrinsicKey = -2;

// Static calibration states (calibration_options.h), like C_mi kept in the window and in the
// marginal prior when knots leave. IMU j's clock offset δ_j [s] (1-D): −16 + j (j < 5); the ids
// −2 … −11 are left to the other calibration states.
inline StateId TimeOffsetKey(int imu) { return -16 + imu; }

// A GP knot of Singer-LIO (SPEC §2, §3): pose T_rm, ϖ, ϖ̇ and the IMU biases [b_a; b_g], one
// bias block per IMU: IMU j's is 8n + 3 + j (j < 5; `bias` is IMU 0's).
struct KnotKeys {
  StateId pose = 0, velocity = 0, acceleration = 0, bias = 0;

  static KnotKeys ForKnot(int64_t n) { return {8 * n, 8 * n + 1, 8 * n + 2, 8 * n + 3}; }
  StateId Bias(int imu) const { return bias + imu; }
  // The blocks of the GP state γ = {T, ϖ, ϖ̇} (the motion prior and the interpolation use these).
  std::vector<StateId> Motion() const { return {pose, velocity, acceleration}; }
};

// The six blocks the interpolation between two knots reads, k first.
inline std::vector<StateId> KnotPair(const KnotKeys& k, const KnotKeys& k1) {
  return {k.pose, k.velocity, k.acceleration, k1.pose, k1.velocity, k1.acceleration};
}

// A navigation state of the IMU-as-input baseline (SPEC §6): pose T_wb, velocity v_w, biases.
struct NavStateKeys {
  StateId pose = 0, velocity = 0, bias = 0;

  static NavStateKeys ForState(int64_t n) { return {8 * n, 8 * n + 1, 8 * n + 3}; }
  std::vector<StateId> All() const { return {pose, velocity, bias}; }
};

}  // namespace ctlio::lio
