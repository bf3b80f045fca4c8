#include "ctlio/study/evaluation.h"

#include <stdexcept>
#include <string>

#include "ctlio/solvers/chi_square.h"

namespace ctlio::study {

ErrorStatistics::ErrorStatistics(int num_times, int dim)
    : dim_(dim),
      error_sum_(num_times, Eigen::VectorXd::Zero(dim)),
      squared_sum_(num_times, Eigen::VectorXd::Zero(dim)),
      nees_sum_(num_times, 0.0) {}

void ErrorStatistics::Add(const Trajectory& traj, const TrajectoryEstimate& est) {
  if (static_cast<int>(est.nodes.size()) != num_times()) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": ErrorStatistics: estimate has a different number of times");
  }
  for (int t = 0; t < num_times(); ++t) {
    const Eigen::VectorXd e = est.mean[t] - traj.truth[est.nodes[t]].head(dim_);
    error_sum_[t] += e;
    squared_sum_[t] += e.cwiseAbs2();
    nees_sum_[t] += e.dot(est.covariance[t].ldlt().solve(e));
  }
  ++count_;
}

void ErrorStatistics::Merge(const ErrorStatistics& o) {
  if (o.num_times() != num_times() || o.dim_ != dim_) {
    throw std::invalid_argument(std::string(__FILE__) + ": ErrorStatistics: shapes differ");
  }
  for (int t = 0; t < num_times(); ++t) {
    error_sum_[t] += o.error_sum_[t];
    squared_sum_[t] += o.squared_sum_[t];
    nees_sum_[t] += o.nees_sum_[t];
  }
  count_ += o.count_;
}

Eigen::VectorXd ErrorStatistics::OverallRmse(int first, int last) const {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(dim_);
  for (int t = first; t < Last(last); ++t) s += squared_sum_[t];
  return (s / (static_cast<double>(count_) * (Last(last) - first))).cwiseSqrt();
}

Eigen::VectorXd ErrorStatistics::OverallMeanError(int first, int last) const {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(dim_);
  for (int t = first; t < Last(last); ++t) s += error_sum_[t];
  return s / (static_cast<double>(count_) * (Last(last) - first));
}

double ErrorStatistics::OverallMeanNees(int first, int last) const {
  double s = 0.0;
  for (int t = first; t < Last(last); ++t) s += nees_sum_[t];
  return s / (static_cast<double>(count_) * (Last(last) - first));
}

double ErrorStatistics::FractionNeesInside(int first, int last) const {
  const double lo = NeesLower(), hi = NeesUpper();
  int inside = 0;
  for (int t = first; t < Last(last); ++t) {
    const double v = MeanNees(t);
    inside += (v >= lo && v <= hi) ? 1 : 0;
  }
  return static_cast<double>(inside) / (Last(last) - first);
}

void NeesBounds(int m, int d, double p, double* lower, double* upper) {
  if (m <= 0 || d <= 0) throw std::invalid_argument(std::string(__FILE__) + ": NeesBounds");
  const double dof = static_cast<double>(m) * d;
  *lower = ChiSquareQuantile(dof, 0.5 * p) / m;
  *upper = ChiSquareQuantile(dof, 1.0 - 0.5 * p) / m;
}

double ErrorStatistics::NeesLower() const {
  double lo, hi;
  NeesBounds(count_, dim_, 0.05, &lo, &hi);
  return lo;
}

double ErrorStatistics::NeesUpper() const {
  double lo, hi;
  NeesBounds(count_, dim_, 0.05, &lo, &hi);
  return hi;
}

}  // namespace ctlio::study
