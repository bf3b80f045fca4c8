// The online calibration's static states as an estimator adds them to its window (both estimators:
// gp_knot_estimator.h, nav_state_estimator.h), each with its Gaussian prior on the configured
// value (calibration_options.h). CalibrationStates (calibration_states.h) finds them there by
// their keys (state_keys.h) to hold, assess and report them.
#pragma once

#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// T_rl (kExtrinsicKey) at config.T_imu_lidar with the prior N(T_imu_lidar, σ) per rotation and
// translation axis (calibration.extrinsic_prior_sigma_deg / _m), left perturbation as
// PoseManifold: [ρ; φ]. Returns the block.
double* AddExtrinsicState(const OdometryConfig& config, SlidingWindow* window);

// δ_j (TimeOffsetKey(j)), 1-D, at the configured offset with its prior
// N(δ̄_j, time_offset_prior_sigma_s²). The marginal priors carry its information on when states
// leave the window.
void AddTimeOffsetState(const CalibrationOptions& calibration, int imu, SlidingWindow* window);

}  // namespace ctlio::lio
