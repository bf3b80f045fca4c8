#include "ctlio/factors/imu/preintegrated_imu.h"

#include <cmath>
#include <stdexcept>

namespace ctlio::imu {

Mat3 DoubleIntegralJacobian(const Vec3& phi) {
  const double t2 = phi.squaredNorm();
  const so3::RodriguesCoefficients k(t2);           // k.c = (θ − sinθ)/θ³
  const double e = so3::RodriguesCoefficientE(t2);  // (θ² + 2cosθ − 2)/(2θ⁴)
  const Mat3 W = so3::Hat(phi);
  return 0.5 * Mat3::Identity() + k.c * W + e * W * W;
}

PreintegratedImu::PreintegratedImu(const Vec6& bias_hat, const ImuNoise& noise,
                                   const Mat3& C_body_sensor)
    : bias_hat_(bias_hat), noise_(noise), C_bs_(C_body_sensor) {
  if (!((C_bs_.transpose() * C_bs_ - Mat3::Identity()).norm() < 1e-6) ||
      C_bs_.determinant() < 0.0) {
    throw std::invalid_argument("PreintegratedImu: C_body_sensor is not a rotation matrix");
  }
  if (!(noise.gyro_noise_density >= 0.0) || !(noise.accel_noise_density >= 0.0) ||
      !(noise.integration_variance >= 0.0)) {
    throw std::invalid_argument("PreintegratedImu: noise densities must be >= 0");
  }
}

void PreintegratedImu::Reset(const Vec6& bias_hat) {
  bias_hat_ = bias_hat;
  delta_t_ = 0.0;
  delta_C_.setIdentity();
  delta_v_.setZero();
  delta_p_.setZero();
  covariance_.setZero();
  bias_jacobian_.setZero();
}

void PreintegratedImu::Integrate(const Vec3& accel, const Vec3& gyro, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("PreintegratedImu::Integrate: dt must be > 0 and finite");
  }
  if (!accel.allFinite() || !gyro.allFinite()) {
    throw std::invalid_argument("PreintegratedImu::Integrate: non-finite IMU sample");
  }
  const Vec3 w = C_bs_ * (gyro - bias_hat_.tail<3>());
  const Vec3 a = C_bs_ * (accel - bias_hat_.head<3>());
  const Vec3 phi = w * dt;
  const double dt2 = dt * dt;

  const Mat3 dC = so3::Exp(phi);
  const Mat3 Jl = so3::LeftJacobian(phi);
  const Mat3 Jr = so3::RightJacobian(phi);
  const Mat3 H = DoubleIntegralJacobian(phi);
  const Vec3 Jl_a = Jl * a;
  const Vec3 H_a = H * a;
  const Mat3& Ck = delta_C_;

  // Linearised step x_{k+1} = A x_k + B_g δω + B_a δa for x = [δφ; δv; δp]
  // (right error on ΔC: ΔC_k Exp(δφ) y ≈ ΔC_k y − ΔC_k y^ δφ).
  Mat9 A = Mat9::Identity();
  A.block<3, 3>(0, 0) = dC.transpose();
  A.block<3, 3>(3, 0) = -Ck * so3::Hat(Jl_a) * dt;
  A.block<3, 3>(6, 0) = -Ck * so3::Hat(H_a) * dt2;
  A.block<3, 3>(6, 3) = Mat3::Identity() * dt;
  // d(J(φ)a)/dφ ≈ −½a^ and d(H(φ)a)/dφ ≈ −⅙a^ (first order in φ = ω̂Δt; the
  // neglected terms are O(|φ|) relative, i.e. O(Δt) over the whole interval,
  // the order Forster's scheme neglects already).
  Eigen::Matrix<double, 9, 3> Bg, Ba;
  Bg.block<3, 3>(0, 0) = Jr * dt;
  Bg.block<3, 3>(3, 0) = Ck * (-0.5 * so3::Hat(a)) * dt2;
  Bg.block<3, 3>(6, 0) = Ck * (-so3::Hat(a) / 6.0) * dt2 * dt;
  Ba.block<3, 3>(0, 0).setZero();
  Ba.block<3, 3>(3, 0) = Ck * Jl * dt;
  Ba.block<3, 3>(6, 0) = Ck * H * dt2;

  // Discrete noise of a sample held over dt: variance σ²/dt (σ a density).
  const double qg = noise_.gyro_noise_density * noise_.gyro_noise_density / dt;
  const double qa = noise_.accel_noise_density * noise_.accel_noise_density / dt;
  covariance_ =
      A * covariance_ * A.transpose() + qg * Bg * Bg.transpose() + qa * Ba * Ba.transpose();
  covariance_.block<3, 3>(6, 6) += noise_.integration_variance * dt * Mat3::Identity();

  // δω = −C_bs δb_g, δa = −C_bs δb_a.
  Mat96 J_next;
  J_next.noalias() = A * bias_jacobian_;
  J_next.leftCols<3>() -= Ba * C_bs_;
  J_next.rightCols<3>() -= Bg * C_bs_;
  bias_jacobian_ = J_next;

  // Mean: exact for a measurement constant in the body frame over dt.
  delta_p_ += delta_v_ * dt + Ck * H_a * dt2;
  delta_v_ += Ck * Jl_a * dt;
  delta_C_ = so3::Normalize(Ck * dC);
  delta_t_ += dt;
}

Mat3 PreintegratedImu::CorrectedRotation(const Vec6& bias) const {
  const Vec3 dbg = bias.tail<3>() - bias_hat_.tail<3>();
  return delta_C_ * so3::Exp(dR_dbg() * dbg);
}

Vec3 PreintegratedImu::CorrectedVelocity(const Vec6& bias) const {
  return delta_v_ + bias_jacobian_.middleRows<3>(3) * (bias - bias_hat_);
}

Vec3 PreintegratedImu::CorrectedPosition(const Vec6& bias) const {
  return delta_p_ + bias_jacobian_.middleRows<3>(6) * (bias - bias_hat_);
}

NavState PreintegratedImu::Predict(const NavState& start, const Vec6& bias,
                                   const Vec3& gravity) const {
  NavState end;
  const double T = delta_t_;
  end.C = start.C * CorrectedRotation(bias);
  end.v = start.v + gravity * T + start.C * CorrectedVelocity(bias);
  end.p = start.p + start.v * T + 0.5 * gravity * T * T + start.C * CorrectedPosition(bias);
  return end;
}

}  // namespace ctlio::imu
