// The baseline's preintegrated IMU factor (preintegrated_imu_factor.h) with the IMU's clock
// offset δ as a state (SPEC §6, online calibration).
//
// The IMU stamps a sample taken at lidar time t as t − δ. The navigation states i, j sit at the
// scan ends t_i, t_j on the lidar clock, so their interval is [t_i − δ, t_j − δ] on the IMU
// clock. It is preintegrated once, at the offset estimate δ̄ of the factor's creation, over
// [a, b] = [t_i − δ̄, t_j − δ̄]; at δ = δ̄ + d the interval is [a − d, b − d]: the samples in
// [a − d, a] join its start, which turns the reference frame of the deltas by Exp(ω_a·d), and
// those in [b − d, b] leave its end. To first order in d, with ω, f the bias-corrected body rate
// and specific force at the ends a and b and the deltas at b̄:
//   ΔC' = Exp(ω_a d)·ΔC·Exp(−ω_b d)        ≈ Exp(d·k_R)·ΔC,  k_R = ω_a − ΔC·ω_b
//   Δv' = Exp(ω_a d)·(Δv + d·f_a − d·ΔC·f_b) ≈ Δv + d·k_v,     k_v = ω_a × Δv + f_a − ΔC·f_b
//   Δp' = Exp(ω_a d)·(Δp − d·Δv + d·f_a·Δt)  ≈ Δp + d·k_p,     k_p = ω_a × Δp − Δv + f_a·Δt
// Δt, and with it gravity's terms, does not change. The residual is preintegrated_imu_factor.h's
// with ΔC(b) → Exp(d·k_R)·ΔC(b), Δv(b) → Δv(b) + d·k_v, Δp(b) → Δp(b) + d·k_p (the rates are
// held at b̄: their bias dependence is second order). The Jacobians by the states keep their form
// (the shift is constant in the bias and sits between ΔC(b)ᵀ and C_iᵀ in E = ΔC'(b)ᵀC_iᵀC_j), and
//   ∂e_R/∂δ = −J_r⁻¹(e_R)·Eᵀ·ΔC(b)ᵀ·k_R,   ∂e_v/∂δ = −k_v,   ∂e_p/∂δ = −k_p.
// The covariance is the interval's at δ̄. Each factor keeps its own δ̄; the estimator takes δ̄ as
// the current estimate when it adds the next one, so d stays of the order of δ's last update.
//
// Parameter blocks (sizes 7, 3, 6, 7, 3, 1): pose_i, v_i, b_i, pose_j, v_j, δ.
#pragma once

#include <ceres/sized_cost_function.h>

#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"

namespace ctlio::imu {

// The raw readings (sensor frame, as given to PreintegratedImu::Integrate) at the interval's
// start a and end b.
struct PreintegrationEnds {
  Vec3 accel_begin = Vec3::Zero();
  Vec3 gyro_begin = Vec3::Zero();
  Vec3 accel_end = Vec3::Zero();
  Vec3 gyro_end = Vec3::Zero();
};

class PreintegratedImuTimeOffsetFactor final
    : public ceres::SizedCostFunction<9, 7, 3, 6, 7, 3, 1> {
 public:
  // `offset_anchor`: δ̄ [s], the offset the interval [a, b] was chosen with. Throws
  // std::invalid_argument as PreintegratedImuFactor does, or for non-finite ends or anchor.
  PreintegratedImuTimeOffsetFactor(const PreintegratedImu& preintegrated, const Vec3& gravity,
                                   const PreintegrationEnds& ends, double offset_anchor);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // k_R, k_v, k_p of the header (d = 0).
  const PreintegrationShift& rates() const { return rates_; }
  double offset_anchor() const { return offset_anchor_; }

 private:
  PreintegratedImu pim_;
  Vec3 gravity_;
  Mat9 sqrt_information_;
  PreintegrationShift rates_;
  double offset_anchor_;
};

}  // namespace ctlio::imu
