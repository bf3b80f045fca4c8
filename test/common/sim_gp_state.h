// The true GP state of a simulated body, for tests that compare the GP or the IMU residuals with
// the simulator's truth.
#pragma once

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::testing {

// x(t) in the map frame = world frame (SPEC §1: T_rm = T_wi⁻¹, ϖ = −twist, its rate likewise).
inline gp::KnotState TrueState(const sim::LidarInertialSim& sim, double t) {
  gp::KnotState x;
  x.pose = sim.WorldFromImu(t).Inverse();
  x.velocity = -sim.BodyTwist(t);
  x.acceleration = -sim.BodyTwistRate(t);
  return x;
}

}  // namespace ctlio::testing
