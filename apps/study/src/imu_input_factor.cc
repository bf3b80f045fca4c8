#include "ctlio/study/imu_input_factor.h"

#include "ctlio/factors/priors/sqrt_information.h"

namespace ctlio::study {

void ImuInputPreintegration::Integrate(const InputPiece& piece) {
  const double d = piece.duration;
  if (!(d > 0.0) || !(piece.variance >= 0.0)) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": ImuInputPreintegration: need duration > 0 and variance >= 0");
  }
  Eigen::Matrix2d A;
  A << 1.0, d, 0.0, 1.0;
  const Eigen::Vector2d B(0.5 * d * d, d);
  delta_p_ += delta_v_ * d + 0.5 * piece.input * d * d;
  delta_v_ += piece.input * d;
  covariance_ = A * covariance_ * A.transpose() + piece.variance * B * B.transpose();
  dt_ += d;
}

ImuInputFactor::ImuInputFactor(const ImuInputPreintegration& preintegration)
    : pre_(preintegration) {
  // A rank-one Σ (one input piece) or a zero Σ cannot whiten the residual.
  if (!(pre_.covariance().determinant() > 0.0)) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": ImuInputFactor: preintegrated covariance is singular (a factor "
                                "needs >= 2 input pieces with positive variance)");
  }
  whiten_ = SqrtInformationFromCovariance<2>(pre_.covariance(), "ImuInputFactor covariance");
}

bool ImuInputFactor::Evaluate(double const* const* x, double* residual, double** jacobians) const {
  const double T = pre_.dt();
  const Eigen::Vector2d e(x[1][0] - x[0][0] - x[0][1] * T - pre_.delta_p(),
                          x[1][1] - x[0][1] - pre_.delta_v());
  Eigen::Map<Eigen::Vector2d> r(residual);
  r = whiten_ * e;
  if (jacobians != nullptr) {
    using RowMat2 = Eigen::Matrix<double, 2, 2, Eigen::RowMajor>;
    if (jacobians[0] != nullptr) {
      Eigen::Matrix2d A;
      A << 1.0, T, 0.0, 1.0;
      Eigen::Map<RowMat2> J0(jacobians[0]);
      J0 = -whiten_ * A;
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMat2> J1(jacobians[1]);
      J1 = whiten_;
    }
  }
  return true;
}

}  // namespace ctlio::study
