// Test-set statistics of the 1D study: per evaluation time, over trajectories, the mean error
// (bias), RMSE per state component and the average NEES with its two-sided 95% χ² bounds
// (M trajectories, state dimension d: M·NEES̄ ~ χ²(M·d) for a consistent estimator).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "ctlio/study/estimators.h"

namespace ctlio::study {

class ErrorStatistics {
 public:
  ErrorStatistics(int num_times, int dim);
  void Add(const Trajectory& traj, const TrajectoryEstimate& estimate);
  void Merge(const ErrorStatistics& other);

  int count() const { return count_; }
  int num_times() const { return static_cast<int>(nees_sum_.size()); }
  int dim() const { return dim_; }
  Eigen::VectorXd MeanError(int t) const { return error_sum_[t] / count_; }
  Eigen::VectorXd Rmse(int t) const { return (squared_sum_[t] / count_).cwiseSqrt(); }
  double MeanNees(int t) const { return nees_sum_[t] / count_; }
  // Over the time indices [first, last) (all by default).
  Eigen::VectorXd OverallRmse(int first = 0, int last = -1) const;
  Eigen::VectorXd OverallMeanError(int first = 0, int last = -1) const;
  double OverallMeanNees(int first = 0, int last = -1) const;
  double FractionNeesInside(int first = 0, int last = -1) const;
  double NeesLower() const;  // χ²_{0.025}(M·d)/M
  double NeesUpper() const;  // χ²_{0.975}(M·d)/M

 private:
  int Last(int last) const { return last < 0 ? num_times() : last; }
  int dim_;
  int count_ = 0;
  std::vector<Eigen::VectorXd> error_sum_;
  std::vector<Eigen::VectorXd> squared_sum_;
  std::vector<double> nees_sum_;
};

// Two-sided (1 − p) interval of the average NEES of m samples of dimension d.
void NeesBounds(int m, int d, double p, double* lower, double* upper);

}  // namespace ctlio::study
