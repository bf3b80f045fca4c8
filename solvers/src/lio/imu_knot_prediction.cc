#include "ctlio/solvers/lio/imu_knot_prediction.h"

#include <algorithm>
#include <array>

#include "ctlio/manifolds/se3.h"

namespace ctlio::lio {

namespace {

// T_rm after h seconds of ϖ moving linearly from w0 to w1 (the midpoint twist; exact for
// constant ϖ, second order otherwise: T_rm(t + h) = Exp(h·ϖ̄)·T_rm(t), SPEC §1).
SE3 Advance(const SE3& T, const Vec6& w0, const Vec6& w1, double h) {
  return SE3::Exp(0.5 * h * (w0 + w1)) * T;
}

// d/dt at τ of the quadratic through (t_j, f_j), j = 0, 1, 2 (Lagrange form).
Vec3 QuadraticSlope(const std::array<double, 3>& t, const std::array<Vec3, 3>& f, double tau) {
  Vec3 slope = Vec3::Zero();
  for (int j = 0; j < 3; ++j) {
    const int k = (j + 1) % 3, l = (j + 2) % 3;
    slope += f[j] * ((tau - t[k]) + (tau - t[l])) / ((t[j] - t[k]) * (t[j] - t[l]));
  }
  return slope;
}

}  // namespace

gp::KnotState PredictKnotWithImu(const gp::KnotState& prev, double t_prev, double t,
                                 const std::vector<TimedImuSample>& samples, const Vec6& bias,
                                 const Mat3& C_mi, const ImuPredictionModel& model) {
  const Vec3 ba = bias.head<3>(), bg = bias.tail<3>();
  const auto angular = [&](const Vec3& gyro) {
    // ϖ_ω = −C_ri(ω_m − b_g) (GyroResidual at zero).
    return Vec3(-(model.mounting.C_ri * (gyro - bg)));
  };
  gp::KnotState x = prev;
  if (!model.has_accelerometer) {
    x.acceleration.head<3>().setZero();
  }
  // ϖ_ω at the knot and at each sample, and ϖ̇_ω at each sample as the slope of the quadratic
  // through it and its neighbours (the two before it at the last sample): the lever-arm term
  // ϖ̇_ω×p reads it, and a two-point quotient lags by half a sample (~4 m/s² at 0.3 m in the fast
  // regime).
  std::vector<double> times = {t_prev};
  std::vector<Vec3> rates = {x.velocity.tail<3>()};
  for (const TimedImuSample& s : samples) {
    times.push_back(std::clamp(s.t, times.back(), t));
    rates.push_back(angular(s.gyro));
  }
  const auto angular_acceleration = [&](size_t i, const Vec3& fallback) {
    const size_t c = std::min(i + 1, times.size() - 1);
    const size_t a = c >= 2 ? c - 2 : 0, b = a + 1;
    constexpr double kMinSpacing = 1e-3;  // s; closer points: the quotient is noise
    if (c == b || times[b] - times[a] < kMinSpacing || times[c] - times[b] < kMinSpacing) {
      return times[c] - times[a] > kMinSpacing ? Vec3((rates[c] - rates[a]) / (times[c] - times[a]))
                                               : fallback;
    }
    return QuadraticSlope({times[a], times[b], times[c]}, {rates[a], rates[b], rates[c]}, times[i]);
  };
  double now = t_prev;
  for (size_t i = 1; i < times.size(); ++i) {
    const TimedImuSample& s = samples[i - 1];
    const double tau = times[i];
    const double h = tau - now;
    Vec6 w1 = x.velocity;
    w1.head<3>() += h * x.acceleration.head<3>();
    w1.tail<3>() = rates[i];
    Vec6 a1 = x.acceleration;
    a1.tail<3>() = angular_acceleration(i, x.acceleration.tail<3>());
    gp::KnotState at_tau{Advance(x.pose, x.velocity, w1, h), w1, a1};
    if (model.has_accelerometer) {
      const imu::internal::AccelResidual residual(s.accel, Mat3::Identity(), model.gravity,
                                                  model.accel_model, model.mounting);
      a1.head<3>() = residual.ZeroingLinearAcceleration(at_tau, C_mi, ba);
      // ϖ_v with the trapezoid of the old and new linear acceleration.
      w1.head<3>() = x.velocity.head<3>() + 0.5 * h * (x.acceleration.head<3>() + a1.head<3>());
      at_tau = {Advance(x.pose, x.velocity, w1, h), w1, a1};
    } else {
      at_tau.velocity.head<3>() = x.velocity.head<3>();
      at_tau.acceleration.head<3>() = x.acceleration.head<3>();
      at_tau.pose = Advance(x.pose, x.velocity, at_tau.velocity, h);
    }
    x = at_tau;
    now = tau;
  }
  if (samples.empty()) {
    // Nothing measured (an IMU gap): constant ϖ, ϖ̇ = 0, the guess without an IMU.
    x.pose = SE3::Exp((t - t_prev) * x.velocity) * x.pose;
    x.acceleration.setZero();
    return x;
  }
  // After the last sample: ϖ̇ held, ϖ linear.
  const double h = t - now;
  Vec6 w1 = x.velocity;
  if (model.has_accelerometer) {
    w1.head<3>() += h * x.acceleration.head<3>();
  }
  x.pose = Advance(x.pose, x.velocity, w1, h);
  x.velocity = w1;
  return x;
}

}  // namespace ctlio::lio
