// The IMU-bias factors both estimators put on their states, with the config's noise (SPEC §3).
#pragma once

#include <ceres/cost_function.h>

#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// imu::BiasRandomWalk between states dt apart; the config gives the variance accumulated per
// bias_walk_period seconds, scaled by Δt (SPEC §3).
ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt);

// Zero-mean prior on the first state's [b_a; b_g] with the config's initial variances.
ceres::CostFunction* MakeInitialBiasPrior(const OdometryConfig& config);

}  // namespace ctlio::lio
