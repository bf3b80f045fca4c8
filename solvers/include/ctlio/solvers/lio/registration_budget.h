// The registration budget of one scan: how many association rounds, and how many solver
// iterations per round, ScanRegistration may spend on it. Three budgets, by what the scan's
// prediction is worth (LidarFrontendOptions):
//   without IMU  a GP method's scan no IMU sample measures (scan_without_imu.h): the lidar alone
//                moves the states from the prior's prediction, which can be degrees off;
//                max_iterations_without_imu × solver_iterations_without_imu;
//   high speed   a scan predicted at ≥ high_speed m/s: the keypoints' map positions move the most
//                per unit of pose error, so rounds that stop short leave a rotation error that
//                grows scan by scan (the baseline's 20 s drives, docs/experiments/scoreboard.md);
//                max_iterations_high_speed × solver_iterations_high_speed;
//   otherwise    max_iterations × solver_iterations.
// A zero count in either special budget means the normal one; rounds still end at convergence.
#pragma once

#include "ctlio/solvers/lio/lidar_frontend_options.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

struct RegistrationBudget {
  int rounds = 0;             // association rounds at most
  int solver_iterations = 0;  // Levenberg–Marquardt iterations per round at most
};

// The budget of a scan: `without_imu` whether no IMU sample measures it, `speed` [m/s] its
// predicted mean speed over its interval. The budget without IMU wins over the high-speed one.
RegistrationBudget ScanBudget(const LidarFrontendOptions& options, bool without_imu, double speed);

// The scan's mean speed [m/s] from its two predicted end poses' positions over `dt` [s] (0 when
// dt is not positive).
double PredictedSpeed(const SE3& previous, const SE3& newest, double dt);

// Registers `term` against `map` within `budget`: the window's solver iterations are the budget's
// for the call and put back after it.
RegistrationSummary RegisterWithin(const RegistrationBudget& budget,
                                   const ScanRegistration& registration, const VoxelMap& map,
                                   LidarTerm* term, SlidingWindow* window);

}  // namespace ctlio::lio
