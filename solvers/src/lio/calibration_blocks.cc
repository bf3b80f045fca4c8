#include "ctlio/solvers/lio/calibration_blocks.h"

#include <cmath>

#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

double* AddExtrinsicState(const OdometryConfig& config, SlidingWindow* window) {
  double* block = window->AddPoseState(kExtrinsicKey, config.T_imu_lidar);
  const CalibrationOptions& c = config.calibration;
  Vec6 sigma;
  sigma << Vec3::Constant(c.extrinsic_prior_sigma_m),
      Vec3::Constant(c.extrinsic_prior_sigma_deg * M_PI / 180.0);
  window->AddResidualBlock(
      new PosePrior(config.T_imu_lidar, sigma.cwiseInverse().asDiagonal().toDenseMatrix()), nullptr,
      {kExtrinsicKey});
  return block;
}

void AddTimeOffsetState(const CalibrationOptions& calibration, int imu, SlidingWindow* window) {
  const Eigen::VectorXd mean = Eigen::VectorXd::Constant(1, calibration.TimeOffset(imu));
  window->AddVectorState(TimeOffsetKey(imu), mean);
  window->AddResidualBlock(new EuclideanPrior<1>(Eigen::Matrix<double, 1, 1>(mean[0]),
                                                 Eigen::Matrix<double, 1, 1>(
                                                     1.0 / calibration.time_offset_prior_sigma_s)),
                           nullptr, {TimeOffsetKey(imu)});
}

}  // namespace ctlio::lio
