// All IMU samples of one IMU on one knot interval [t_k, t_{k+1}] as ONE residual block: sample i
// gives rows 6i…6i+2, its gyro residual, and 6i+3…6i+5, its accelerometer residual (3i…3i+2, gyro
// only, without the accelerometer: lidar_gyro). Each row is the residual of the per-sample
// factors, evaluated by the same code (imu_residual.h: GyroResidual, AccelResidual and their
// chains; the models and Jacobians are documented in imu_measurement.h), on the state x(τ) of
// the one GP interpolation module (gp::GpInterpolator::StateRows), formed once per sample for
// both sensors and, at fixed times, with the interval's local variables γ_{k+1}
// (gp::LocalVariables, knot_state.h) formed once per evaluation for all samples (bit-identical to
// forming them per sample, interpolator.h). What is batched is Ceres' per-block machinery — one
// evaluation call, one validity check, one loss correction and one manifold product per interval
// instead of two blocks per sample — and the interpolation's knot-dependent part.
//
// The accelerometer's robust loss, per sample as before. Ceres robustifies a whole residual block
// by ρ(‖r‖²), so a block of N samples with a Ceres loss would be one robust term, not N. The
// block applies each sample's loss itself, as Ceres' Corrector does to a one-sample block when
// ρ'' ≤ 0 (Cauchy, Huber, SoftL1, Arctan): the sample's three accelerometer rows are
// √ρ'(‖e_a‖²)·e_a with Jacobian √ρ'(‖e_a‖²)·∂e_a, and one constant row (zero Jacobian) closes the
// cost,
//   r_last = √(Σ_i ρ(‖e_a,i‖²) − ρ'(‖e_a,i‖²)·‖e_a,i‖²)   (≥ 0 for a concave ρ with ρ(0) = 0),
// so ½‖r‖² = ½Σ_i (‖e_g,i‖² + ρ(‖e_a,i‖²)), the cost of the 2N per-sample blocks, with their
// gradient and Gauss–Newton Hessian (the LM step, its acceptance test, and the marginalisation's
// linearisation, which applies no loss to this block), equal up to rounding (test
// imu.ImuIntervalBatch.*). The same construction as the lidar batch
// (lidar/continuous_point_to_plane_batch.h). A loss with ρ'' > 0 somewhere has no such constant
// row: Evaluate returns false there. Without a loss there is no extra row and the block is an
// ordinary cost function (its Jacobians are checked numerically).
//
// Shared interpolations. Given one gp::SharedStateInterpolation per sample (the second
// constructor), the block reads x(τ_i) from it: a window's evaluation callback prepares them once
// per evaluation point, with the Jacobians and the interval's local variables shared with the
// lidar interpolations on the same knots, and on several threads with window.threads
// (solvers/shared_interpolation_callback.h); the Jacobian evaluation at an accepted point then
// reads what the cost evaluation there prepared. Without them the block interpolates itself, on
// every evaluation (what a caller outside a window's solve, e.g. a gradient check, gets).
//
// Time offset (imu_gyro_time_offset.h, imu_accel_time_offset.h): with estimate_time_offset each
// sample's time is its stamp t and it measures x(t + δ), δ a last parameter block; the
// interpolation is formed at τ = t + δ on every evaluation (clamped to the interval, as the
// per-sample factors), once per sample for both sensors. A held offset is the fixed-time form
// with τ = clamp(t + δ) given as the sample's time.
//
// Parameter blocks: pose_k (7, PoseManifold), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1, b_k (6),
// b_k+1 (6), with the accelerometer C_mi (4, RotationManifold), with the estimated offset δ (1).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <optional>
#include <vector>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/factors/imu/imu_residual.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

class ImuIntervalBatch final : public ceres::CostFunction {
 public:
  struct Sample {
    // τ ∈ [t_k, t_{k+1}] at fixed times; the stamp t (τ = t + δ) with an estimated offset.
    double time = 0.0;
    Vec3 gyro = Vec3::Zero();   // ω_m [rad/s]
    Vec3 accel = Vec3::Zero();  // f_m [m/s²]
  };
  struct Options {
    Mat3 gyro_covariance = Mat3::Identity();   // of one sample
    Mat3 accel_covariance = Mat3::Identity();  // of one sample
    double gravity = 9.81;                     // |g|
    AccelModel accel_model = AccelModel::kSpecificForce;
    ImuMounting mounting;
    bool accelerometer = true;          // false: the gyro rows only, no C_mi block
    bool estimate_time_offset = false;  // a last block δ, each sample at its stamp + δ
  };

  // At least one sample; at fixed times each in [t_k, t_k1] (throws std::invalid_argument
  // otherwise). `accel_loss` (nullable, shared) is each sample's accelerometer loss.
  ImuIntervalBatch(const gp::SingerModel<6>& model, double t_k, double t_k1,
                   std::vector<Sample> samples, const Options& options,
                   std::shared_ptr<const ceres::LossFunction> accel_loss = nullptr);

  // At fixed times, reading sample i's state from states[i] (at τ_i = samples[i].time between the
  // interval's knots, its six knot blocks those of this block), which the block asks for the
  // rows it reads; not with estimate_time_offset.
  ImuIntervalBatch(const gp::SingerModel<6>& model, double t_k, double t_k1,
                   std::vector<Sample> samples,
                   std::vector<std::shared_ptr<gp::SharedStateInterpolation>> states,
                   const Options& options,
                   std::shared_ptr<const ceres::LossFunction> accel_loss = nullptr);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The whitened χ² without the loss, Σ_i ‖e_a,i‖² and Σ_i ‖e_g,i‖², at `parameters` (the IMU
  // consistency check, solvers/lio/imu_consistency.h); false if a value is not finite.
  bool ChiSquare(double const* const* parameters, double* accel, double* gyro) const;

  size_t size() const { return samples_.size(); }
  bool accelerometer() const { return options_.accelerometer; }
  const ceres::LossFunction* loss() const { return loss_.get(); }
  // The parameter block of C_mi (−1 without the accelerometer) and of δ (−1 if held).
  int gravity_block() const { return options_.accelerometer ? 8 : -1; }
  int offset_block() const {
    return options_.estimate_time_offset ? (options_.accelerometer ? 9 : 8) : -1;
  }

 private:
  // x(τ_i), its knot Jacobians' rows (with `knot_jacobians`), its rate (with `rate`) and s(τ_i).
  ImuIntervalBatch(const gp::SingerModel<6>& model, double t_k, double t_k1,
                   std::vector<Sample> samples, const Options& options,
                   std::shared_ptr<const ceres::LossFunction> accel_loss, bool own_interpolators);

  struct View {
    const gp::KnotState* x;
    const gp::StateJacobian *J_k, *J_k1;
    const gp::StateRate* rate;
    double s, ds_ddelta;
  };
  // From the shared state, or formed into the scratch: at a fixed time from the interval's local
  // variables `local` (k: knot k's values), with the estimated offset at the stamp + δ.
  View Interpolate(size_t i, double const* const* parameters, const gp::KnotState& k,
                   const std::optional<gp::LocalVariables>& local, bool knot_jacobians, bool rate,
                   internal::TimeShiftedState* scratch,
                   gp::SharedStateInterpolation::Result* shared_scratch) const;
  // The local variables at `parameters` for the samples not read from shared states.
  std::optional<gp::LocalVariables> Local(double const* const* parameters, const gp::KnotState& k,
                                          bool knot_jacobians) const;

  gp::SingerModel<6> model_;
  double t_k_, t_k1_;
  std::vector<Sample> samples_;
  Options options_;
  std::shared_ptr<const ceres::LossFunction> loss_;
  std::vector<gp::GpInterpolator> interpolators_;  // at fixed times, unshared, one per sample
  std::vector<std::shared_ptr<const gp::SharedStateInterpolation>> states_;  // or shared ones
  std::vector<internal::GyroResidual> gyro_;
  std::vector<internal::AccelResidual> accel_;
  unsigned rows_;  // the state rows both residuals read
  int rows_per_sample_;
};

}  // namespace ctlio::imu
