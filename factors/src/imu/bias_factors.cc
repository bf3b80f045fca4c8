#include "ctlio/factors/imu/bias_factors.h"

#include <cmath>
#include <stdexcept>

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio::imu {

BiasRandomWalk::BiasRandomWalk(double accel_psd, double gyro_psd, double dt) {
  if (!(accel_psd > 0.0) || !(gyro_psd > 0.0) || !(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("BiasRandomWalk: densities and dt must be positive and finite");
  }
  sqrt_info_.head<3>().setConstant(1.0 / std::sqrt(accel_psd * dt));
  sqrt_info_.tail<3>().setConstant(1.0 / std::sqrt(gyro_psd * dt));
}

bool BiasRandomWalk::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const Eigen::Map<const Vec6> b0(parameters[0]), b1(parameters[1]);
  Eigen::Map<Vec6>{residuals} = sqrt_info_.cwiseProduct(b1 - b0);
  if (jacobians != nullptr) {
    using Jac = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
    if (jacobians[0] != nullptr)
      Eigen::Map<Jac>{jacobians[0]} = -sqrt_info_.asDiagonal().toDenseMatrix();
    if (jacobians[1] != nullptr)
      Eigen::Map<Jac>{jacobians[1]} = sqrt_info_.asDiagonal().toDenseMatrix();
  }
  return true;
}

BiasPrior::BiasPrior(const Vec6& mean, const Mat6& covariance)
    : mean_(mean), sqrt_information_(SqrtInformationFromCovariance<6>(covariance, "BiasPrior")) {}

bool BiasPrior::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  const Eigen::Map<const Vec6> b(parameters[0]);
  Eigen::Map<Vec6>{residuals} = sqrt_information_ * (b - mean_);
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>{jacobians[0]} = sqrt_information_;
  }
  return true;
}

}  // namespace ctlio::imu
