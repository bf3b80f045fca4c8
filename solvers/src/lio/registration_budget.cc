#include "ctlio/solvers/lio/registration_budget.h"

namespace ctlio::lio {

RegistrationBudget ScanBudget(const LidarFrontendOptions& options, bool without_imu, double speed) {
  RegistrationBudget budget{options.max_iterations, options.solver_iterations};
  int rounds = 0, iterations = 0;
  if (without_imu) {
    rounds = options.max_iterations_without_imu;
    iterations = options.solver_iterations_without_imu;
  } else if (options.high_speed > 0.0 && speed >= options.high_speed) {
    rounds = options.max_iterations_high_speed;
    iterations = options.solver_iterations_high_speed;
  }
  if (rounds > 0) budget.rounds = rounds;
  if (iterations > 0) budget.solver_iterations = iterations;
  return budget;
}

double PredictedSpeed(const SE3& previous, const SE3& newest, double dt) {
  if (!(dt > 0.0)) return 0.0;
  return (newest.translation() - previous.translation()).norm() / dt;
}

RegistrationSummary RegisterWithin(const RegistrationBudget& budget,
                                   const ScanRegistration& registration, const VoxelMap& map,
                                   LidarTerm* term, SlidingWindow* window) {
  // The window's own count comes back however Register leaves (it may throw).
  struct Restore {
    int& value;
    const int kept;
    ~Restore() { value = kept; }
  } restore{window->options().solver.max_num_iterations,
            window->options().solver.max_num_iterations};
  restore.value = budget.solver_iterations;
  return registration.Register(map, term, window, budget.rounds);
}

}  // namespace ctlio::lio
