// GpKnotEstimator's IMU terms: every gyro and accelerometer sample of a knot interval as a
// measurement of the interpolated continuous-time state (SPEC §3), either
// one block per interval (ImuIntervalBatch, the default) or one block per sample.
#include <ceres/loss_function.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "ctlio/factors/imu/imu_accel_time_offset.h"
#include "ctlio/factors/imu/imu_gyro_time_offset.h"
#include "ctlio/factors/imu/imu_interval_batch.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/solvers/lio/gp_knot_estimator.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

void GpKnotEstimator::AddImuMeasurements(const Knot& prev, const Knot& k, int imu_index,
                                         const std::vector<ImuSample>& imu, SlidingWindow* window,
                                         ScanResult* result) {
  // On a sweep the motion rule split, at least its variance floors (knot_spacing.h).
  const AdaptiveKnotOptions& adaptive = config_.adaptive_knots;
  const double gyro_variance =
      split_sweep_ ? std::max(config_.GyroVariance(imu_index), adaptive.gyro_variance_floor)
                   : config_.GyroVariance(imu_index);
  const double accel_variance =
      split_sweep_ ? std::max(config_.AccelVariance(imu_index), adaptive.accel_variance_floor)
                   : config_.AccelVariance(imu_index);
  const Mat3 gyro_cov = gyro_variance * Mat3::Identity();
  const Mat3 accel_cov = accel_variance * Mat3::Identity();
  const imu::ImuMounting& mounting = mountings_[imu_index];
  const imu::AccelModel accel_model = config_.exact_specific_force ? imu::AccelModel::kSpecificForce
                                                                   : imu::AccelModel::kBodyCentric;
  std::vector<StateId> gyro_states = KnotPair(prev.keys, k.keys);
  gyro_states.push_back(prev.keys.Bias(imu_index));
  gyro_states.push_back(k.keys.Bias(imu_index));
  std::vector<StateId> accel_states = gyro_states;
  accel_states.push_back(kGravityKey);
  // One loss per scan, shared by its accelerometer residuals (the window ref-counts it).
  // Its scale: imu.accel_loss_scale, or the relaxed one once the bias is known (the window holds
  // one interval, so the intervals added from then on are all of it; accel_loss_schedule.h).
  const double accel_loss_scale = accel_loss_.scale(imu_index);
  std::unique_ptr<ceres::LossFunction> accel_loss(
      accel_loss_scale > 0 ? new ceres::CauchyLoss(accel_loss_scale) : nullptr);
  bool accel_loss_used = false;
  const gp::KnotBlocks knots = {prev.pose, prev.velocity, prev.acceleration,
                                k.pose,    k.velocity,    k.acceleration};
  if (config_.imu_residual_blocks == "interval") {
    // One block for the interval's samples, the per-sample residuals below in one evaluation
    // (imu_interval_batch.h), with each accelerometer sample's loss inside the block.
    if (imu.empty()) return;
    imu::ImuIntervalBatch::Options o;
    o.gyro_covariance = gyro_cov;
    o.accel_covariance = accel_cov;
    o.gravity = config_.gravity;
    o.accel_model = accel_model;
    o.mounting = mounting;
    o.accelerometer = config_.method == LioMethod::kSingerLio;
    o.estimate_time_offset = time_offsets() && config_.calibration.estimate_time_offset;
    const double delta = time_offsets() ? TimeOffset(imu_index, *window) : 0.0;
    std::vector<imu::ImuIntervalBatch::Sample> samples;
    std::vector<std::shared_ptr<gp::SharedStateInterpolation>> shared;
    samples.reserve(imu.size());
    for (const ImuSample& s : imu) {
      const double stamp = imu_.Seconds(s.t_ns);
      // As below: the stamp (offset estimated), the stamp + a held offset on the interval, or
      // the stamp.
      const double time = !time_offsets() || o.estimate_time_offset
                              ? stamp
                              : std::clamp(stamp + delta, prev.t, k.t);
      samples.push_back({time, s.gyro, s.accel});
      if (o.estimate_time_offset) continue;
      // At a fixed time the window's evaluation callback prepares the sample's state once per
      // evaluation point, as for the per-sample blocks.
      shared.push_back(
          std::make_shared<gp::SharedStateInterpolation>(model_, prev.t, k.t, time, knots));
      window->shared_interpolations().Add(shared.back());
    }
    std::vector<StateId> states = o.accelerometer ? accel_states : gyro_states;
    if (o.estimate_time_offset) states.push_back(TimeOffsetKey(imu_index));
    std::shared_ptr<const ceres::LossFunction> loss(std::move(accel_loss));
    auto* batch = o.estimate_time_offset
                      ? new imu::ImuIntervalBatch(model_, prev.t, k.t, std::move(samples), o, loss)
                      : new imu::ImuIntervalBatch(model_, prev.t, k.t, std::move(samples),
                                                  std::move(shared), o, loss);
    const ceres::ResidualBlockId id = window->AddResidualBlock(batch, nullptr, states);
    (o.accelerometer ? imu_blocks_.accel : imu_blocks_.gyro).push_back(id);
    result->imu_residuals += static_cast<int>((o.accelerometer ? 2 : 1) * imu.size());
    return;
  }
  if (time_offsets()) {
    const double delta = TimeOffset(imu_index, *window);
    for (const ImuSample& s : imu) {
      const double stamp = imu_.Seconds(s.t_ns);
      if (config_.calibration.estimate_time_offset) {
        std::vector<StateId> g = gyro_states, a = accel_states;
        g.push_back(TimeOffsetKey(imu_index));
        a.push_back(TimeOffsetKey(imu_index));
        imu_blocks_.gyro.push_back(
            window->AddResidualBlock(new imu::ImuGyroMeasurementWithTimeOffset(
                                         model_, prev.t, k.t, stamp, s.gyro, gyro_cov, mounting),
                                     nullptr, g));
        ++result->imu_residuals;
        if (config_.method == LioMethod::kSingerLio) {
          imu_blocks_.accel.push_back(window->AddResidualBlock(
              new imu::ImuAccelMeasurementWithTimeOffset(model_, prev.t, k.t, stamp, s.accel,
                                                         accel_cov, config_.gravity, accel_model,
                                                         mounting),
              accel_loss.get(), a));
          accel_loss_used = accel_loss != nullptr;
          ++result->imu_residuals;
        }
        continue;
      }
      // A configured offset, held: the fixed-time factors at t + δ (on the interval).
      const double tau = std::clamp(stamp + delta, prev.t, k.t);
      imu_blocks_.gyro.push_back(window->AddResidualBlock(
          new imu::ImuGyroMeasurement(model_, prev.t, k.t, tau, s.gyro, gyro_cov, mounting),
          nullptr, gyro_states));
      ++result->imu_residuals;
      if (config_.method == LioMethod::kSingerLio) {
        imu_blocks_.accel.push_back(window->AddResidualBlock(
            new imu::ImuAccelMeasurement(model_, prev.t, k.t, tau, s.accel, accel_cov,
                                         config_.gravity, accel_model, mounting),
            accel_loss.get(), accel_states));
        accel_loss_used = accel_loss != nullptr;
        ++result->imu_residuals;
      }
    }
    if (accel_loss_used) accel_loss.release();
    return;
  }
  for (const ImuSample& s : imu) {
    const double tau = imu_.Seconds(s.t_ns);
    // The sample's state at τ, interpolated once per evaluation for its gyro and accelerometer
    // residuals (the window's evaluation callback prepares it).
    const auto state =
        std::make_shared<gp::SharedStateInterpolation>(model_, prev.t, k.t, tau, knots);
    window->shared_interpolations().Add(state);
    imu_blocks_.gyro.push_back(window->AddResidualBlock(
        new imu::ImuGyroMeasurement(state, s.gyro, gyro_cov, mounting), nullptr, gyro_states));
    ++result->imu_residuals;
    if (config_.method == LioMethod::kSingerLio) {
      imu_blocks_.accel.push_back(window->AddResidualBlock(
          new imu::ImuAccelMeasurement(state, s.accel, accel_cov, config_.gravity, accel_model,
                                       mounting),
          accel_loss.get(), accel_states));
      accel_loss_used = accel_loss != nullptr;
      ++result->imu_residuals;
    }
  }
  if (accel_loss_used) accel_loss.release();
}

}  // namespace ctlio::lio
