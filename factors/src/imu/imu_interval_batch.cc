#include "ctlio/factors/imu/imu_interval_batch.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::imu {

using internal::WriteKnotJacobians;

namespace {

constexpr int kBlockSizes[10] = {7, 6, 6, 7, 6, 6, 6, 6, 4, 1};

// Rows `row`… of parameter block b's Jacobian (row-major, kBlockSizes[b] columns), or null.
double* JacobianRow(double** jacobians, int b, int row) {
  return jacobians[b] != nullptr ? jacobians[b] + row * kBlockSizes[b] : nullptr;
}

}  // namespace

ImuIntervalBatch::ImuIntervalBatch(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                   std::vector<Sample> samples, const Options& options,
                                   std::shared_ptr<const ceres::LossFunction> accel_loss)
    : ImuIntervalBatch(model, t_k, t_k1, std::move(samples), options, std::move(accel_loss),
                       /*own_interpolators=*/true) {}

ImuIntervalBatch::ImuIntervalBatch(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                   std::vector<Sample> samples, const Options& options,
                                   std::shared_ptr<const ceres::LossFunction> accel_loss,
                                   bool own_interpolators)
    : model_(model),
      t_k_(t_k),
      t_k1_(t_k1),
      samples_(std::move(samples)),
      options_(options),
      loss_(options.accelerometer ? std::move(accel_loss) : nullptr),
      rows_(gp::kAngularVelocityRows |
            (options.accelerometer
                 ? internal::AccelResidual::Rows(options.accel_model, options.mounting)
                 : 0u)),
      rows_per_sample_(options.accelerometer ? 6 : 3) {
  if (samples_.empty()) throw std::invalid_argument("ImuIntervalBatch: no samples");
  gp::GpInterpolator(model_, t_k, t_k1, t_k);  // the interval's checks (t_k < t_{k+1}), once
  gyro_.reserve(samples_.size());
  for (const Sample& s : samples_) {
    if (!options_.estimate_time_offset) {
      if (!(s.time >= t_k && s.time <= t_k1)) {
        throw std::invalid_argument("ImuIntervalBatch: a sample's time is outside the interval");
      }
      if (own_interpolators) interpolators_.emplace_back(model_, t_k, t_k1, s.time);
    }
    gyro_.emplace_back(s.gyro, options_.gyro_covariance, options_.mounting);
    if (options_.accelerometer) {
      accel_.emplace_back(s.accel, options_.accel_covariance, options_.gravity,
                          options_.accel_model, options_.mounting);
    }
  }
  set_num_residuals(rows_per_sample_ * static_cast<int>(samples_.size()) +
                    (loss_ != nullptr ? 1 : 0));
  const int blocks = 8 + (options_.accelerometer ? 1 : 0) + (options_.estimate_time_offset ? 1 : 0);
  for (int b = 0; b < blocks; ++b) {
    // The δ block is the last one, after C_mi when there is one.
    const int size = b == offset_block() ? 1 : kBlockSizes[b];
    mutable_parameter_block_sizes()->push_back(size);
  }
}

ImuIntervalBatch::ImuIntervalBatch(
    const gp::SingerModel<6>& model, double t_k, double t_k1, std::vector<Sample> samples,
    std::vector<std::shared_ptr<gp::SharedStateInterpolation>> states, const Options& options,
    std::shared_ptr<const ceres::LossFunction> accel_loss)
    : ImuIntervalBatch(model, t_k, t_k1, std::move(samples), options, std::move(accel_loss),
                       /*own_interpolators=*/false) {
  if (options_.estimate_time_offset || states.size() != samples_.size()) {
    throw std::invalid_argument(
        "ImuIntervalBatch: shared states need fixed times and one state per sample");
  }
  for (auto& state : states) {
    state->AddRows(rows_);
    states_.push_back(std::move(state));
  }
}

std::optional<gp::LocalVariables> ImuIntervalBatch::Local(double const* const* parameters,
                                                          const gp::KnotState& k,
                                                          bool knot_jacobians) const {
  if (options_.estimate_time_offset || !states_.empty()) return std::nullopt;
  return gp::LocalVariables(k, gp::ReadKnotState(parameters[3], parameters[4], parameters[5]),
                            knot_jacobians);
}

ImuIntervalBatch::View ImuIntervalBatch::Interpolate(
    size_t i, double const* const* parameters, const gp::KnotState& k,
    const std::optional<gp::LocalVariables>& local, bool knot_jacobians, bool rate,
    internal::TimeShiftedState* scratch,
    gp::SharedStateInterpolation::Result* shared_scratch) const {
  if (options_.estimate_time_offset) {
    internal::InterpolateShifted(model_, t_k_, t_k1_, samples_[i].time,
                                 parameters[offset_block()][0], rows_, parameters, knot_jacobians,
                                 rate, scratch);
    return {&scratch->x,    &scratch->J_k, &scratch->J_k1,
            &scratch->rate, scratch->s,    scratch->ds_ddelta};
  }
  if (!states_.empty()) {
    const gp::SharedStateInterpolation::Result& r =
        states_[i]->State(parameters, rows_, knot_jacobians, shared_scratch);
    return {&r.x, &r.J_k, &r.J_k1, nullptr, states_[i]->fraction(), 0.0};
  }
  interpolators_[i].StateRows(k, *local, rows_, &scratch->x,
                              knot_jacobians ? &scratch->J_k : nullptr,
                              knot_jacobians ? &scratch->J_k1 : nullptr);
  // As gp::SharedStateInterpolation::fraction().
  return {&scratch->x,
          &scratch->J_k,
          &scratch->J_k1,
          nullptr,
          (samples_[i].time - t_k_) / (t_k1_ - t_k_),
          0.0};
}

bool ImuIntervalBatch::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const bool accel = options_.accelerometer;
  const int g_block = gravity_block(), d_block = offset_block();
  const bool knot_jacobians = internal::NeedsKnotJacobians(jacobians);
  const bool rate = d_block >= 0 && jacobians != nullptr && jacobians[d_block] != nullptr;
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const Mat3 C_mi = accel ? RotationManifold::Rotation(parameters[g_block]) : Mat3::Identity();
  const gp::KnotState k = gp::ReadKnotState(parameters[0], parameters[1], parameters[2]);
  // At fixed times, unshared, the knot-dependent part γ_{k+1} once for every sample.
  const std::optional<gp::LocalVariables> local = Local(parameters, k, knot_jacobians);
  const int num_blocks = static_cast<int>(parameter_block_sizes().size());
  internal::TimeShiftedState scratch;
  gp::SharedStateInterpolation::Result shared_scratch;
  internal::AccelResidual::Linearisation lin;
  double cost_gap = 0.0;  // Σ ρ − ρ'·‖e_a‖², in sample order
  for (size_t i = 0; i < samples_.size(); ++i) {
    const View st =
        Interpolate(i, parameters, k, local, knot_jacobians, rate, &scratch, &shared_scratch);
    const double s = st.s;
    const int row_g = rows_per_sample_ * static_cast<int>(i), row_a = row_g + 3;
    // Gyro rows, as ImuGyroMeasurement(WithTimeOffset).
    const Vec3 bg = (1.0 - s) * b_k.tail<3>() + s * b_k1.tail<3>();
    Eigen::Map<Vec3>{residuals + row_g} = gyro_[i].Evaluate(*st.x, bg);
    if (jacobians != nullptr) {
      if (knot_jacobians) {
        WriteKnotJacobians(gyro_[i].Chain(*st.J_k), parameters[0], JacobianRow(jacobians, 0, row_g),
                           JacobianRow(jacobians, 1, row_g), JacobianRow(jacobians, 2, row_g));
        WriteKnotJacobians(gyro_[i].Chain(*st.J_k1), parameters[3],
                           JacobianRow(jacobians, 3, row_g), JacobianRow(jacobians, 4, row_g),
                           JacobianRow(jacobians, 5, row_g));
      }
      internal::WriteBiasJacobians(gyro_[i].sqrt_information(), s, 3,
                                   JacobianRow(jacobians, 6, row_g),
                                   JacobianRow(jacobians, 7, row_g));
      if (g_block >= 0 && jacobians[g_block] != nullptr) {
        std::fill_n(jacobians[g_block] + row_g * 4, 3 * 4, 0.0);
      }
      if (rate) {
        // ∂e_g/∂δ = D·ẋ(τ) − S·db_g/dτ (imu_gyro_time_offset.h).
        Eigen::Map<Vec3>{jacobians[d_block] + row_g} =
            gyro_[i].Chain(*st.rate) -
            st.ds_ddelta * gyro_[i].sqrt_information() * (b_k1.tail<3>() - b_k.tail<3>());
      }
    }
    if (!accel) continue;

    // Accelerometer rows, as ImuAccelMeasurement(WithTimeOffset), then the sample's loss.
    const Vec3 ba = (1.0 - s) * b_k.head<3>() + s * b_k1.head<3>();
    const Vec3 e = accel_[i].Evaluate(*st.x, C_mi, ba, jacobians != nullptr ? &lin : nullptr);
    double scale = 1.0;
    if (loss_ != nullptr) {
      const double sq_norm = e.squaredNorm();
      double rho[3];
      loss_->Evaluate(sq_norm, rho);
      if (rho[2] > 0.0) return false;  // not concave here: no exact constant row (header)
      scale = std::sqrt(rho[1]);
      cost_gap += rho[0] - rho[1] * sq_norm;
    }
    Eigen::Map<Vec3>{residuals + row_a} = scale * e;
    if (jacobians == nullptr) continue;
    if (knot_jacobians) {
      WriteKnotJacobians(accel_[i].Chain(lin, *st.J_k), parameters[0],
                         JacobianRow(jacobians, 0, row_a), JacobianRow(jacobians, 1, row_a),
                         JacobianRow(jacobians, 2, row_a));
      WriteKnotJacobians(accel_[i].Chain(lin, *st.J_k1), parameters[3],
                         JacobianRow(jacobians, 3, row_a), JacobianRow(jacobians, 4, row_a),
                         JacobianRow(jacobians, 5, row_a));
    }
    internal::WriteBiasJacobians(accel_[i].sqrt_information(), s, 0,
                                 JacobianRow(jacobians, 6, row_a),
                                 JacobianRow(jacobians, 7, row_a));
    if (jacobians[g_block] != nullptr) {
      LiftRotationJacobian<3>(accel_[i].GravityJacobian(lin), parameters[g_block],
                              jacobians[g_block] + row_a * 4);
    }
    if (rate) {
      // ∂e_a/∂δ = D·ẋ(τ) − S·db_a/dτ (imu_accel_time_offset.h).
      Eigen::Map<Vec3>{jacobians[d_block] + row_a} =
          accel_[i].Chain(lin, *st.rate) -
          st.ds_ddelta * accel_[i].sqrt_information() * (b_k1.head<3>() - b_k.head<3>());
    }
    if (scale == 1.0) continue;
    for (int b = 0; b < num_blocks; ++b) {
      if (jacobians[b] == nullptr) continue;
      const int size = parameter_block_sizes()[b];
      double* row = jacobians[b] + row_a * size;
      for (int c = 0; c < 3 * size; ++c) row[c] *= scale;
    }
  }
  if (loss_ == nullptr) return true;
  const int last = num_residuals() - 1;
  residuals[last] = std::sqrt(std::max(cost_gap, 0.0));  // clamps rounding below 0 only
  if (jacobians != nullptr) {
    for (int b = 0; b < num_blocks; ++b) {
      if (jacobians[b] == nullptr) continue;
      const int size = parameter_block_sizes()[b];
      std::fill_n(jacobians[b] + last * size, size, 0.0);
    }
  }
  return true;
}

bool ImuIntervalBatch::ChiSquare(double const* const* parameters, double* accel,
                                 double* gyro) const {
  *accel = *gyro = 0.0;
  const Eigen::Map<const Vec6> b_k(parameters[6]), b_k1(parameters[7]);
  const Mat3 C_mi =
      options_.accelerometer ? RotationManifold::Rotation(parameters[8]) : Mat3::Identity();
  const gp::KnotState k = gp::ReadKnotState(parameters[0], parameters[1], parameters[2]);
  const std::optional<gp::LocalVariables> local = Local(parameters, k, false);
  internal::TimeShiftedState scratch;
  gp::SharedStateInterpolation::Result shared_scratch;
  for (size_t i = 0; i < samples_.size(); ++i) {
    const View st = Interpolate(i, parameters, k, local, false, false, &scratch, &shared_scratch);
    const double s = st.s;
    *gyro += gyro_[i].Evaluate(*st.x, (1.0 - s) * b_k.tail<3>() + s * b_k1.tail<3>()).squaredNorm();
    if (!options_.accelerometer) continue;
    *accel += accel_[i]
                  .Evaluate(*st.x, C_mi, (1.0 - s) * b_k.head<3>() + s * b_k1.head<3>(), nullptr)
                  .squaredNorm();
  }
  return std::isfinite(*accel) && std::isfinite(*gyro);
}

}  // namespace ctlio::imu
