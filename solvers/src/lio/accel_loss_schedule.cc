#include "ctlio/solvers/lio/accel_loss_schedule.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace ctlio::lio {

AccelLossSchedule::AccelLossSchedule(double scale, double relax_bias_sigma, double relaxed_scale,
                                     int num_imus)
    : scale_(scale),
      relax_bias_sigma_(relax_bias_sigma),
      relaxed_scale_(relaxed_scale),
      relaxed_(static_cast<size_t>(std::max(num_imus, 0)), false),
      last_sigma_(static_cast<size_t>(std::max(num_imus, 0)), 0.0) {}

bool AccelLossSchedule::Watching(int imu) const { return enabled() && !relaxed_[imu]; }

double AccelLossSchedule::LargestSigma(const Mat3& covariance) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!covariance.allFinite()) return kNaN;
  const Mat3 symmetric = 0.5 * (covariance + covariance.transpose());
  const double largest = Eigen::SelfAdjointEigenSolver<Mat3>(symmetric).eigenvalues().maxCoeff();
  return largest > 0.0 ? std::sqrt(largest) : kNaN;
}

void AccelLossSchedule::Observe(int imu, const Mat3& accel_bias_covariance) {
  if (!Watching(imu)) return;
  const double sigma = LargestSigma(accel_bias_covariance);
  last_sigma_[imu] = std::isnan(sigma) ? 0.0 : sigma;
  if (sigma < relax_bias_sigma_) relaxed_[imu] = true;  // false for NaN
}

}  // namespace ctlio::lio
