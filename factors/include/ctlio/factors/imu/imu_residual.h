// The gyro and accelerometer residuals of one IMU sample given the interpolated state x(τ), and
// their chain D·M onto any 18-row matrix M of state variations (M = ∂x(τ)/∂knot: the knot
// Jacobians; M = ẋ(τ): the derivative with respect to the sample's time). Written once, read by
// the measurement factors at a fixed time (imu_measurement.h) and at a time shifted by an
// estimated clock offset (imu_gyro_time_offset.h, imu_accel_time_offset.h); the models, the
// mounting and the Jacobians are documented in imu_measurement.h.
#pragma once

#include <Eigen/Core>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/so3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

// The accelerometer model (imu_measurement.h, SPEC §3). kSpecificForce, what an accelerometer
// measures, is the library's default; kBodyCentric is the paper's approximation, selectable for
// reproducing it (it leaves out ω×v, ~|ω||v| m/s² of systematic error in turns).
enum class AccelModel {
  kBodyCentric,    // the paper's approximation: ϖ̇_v as the body acceleration, no ω×v
  kSpecificForce,  // exact specific force, with ω×v (the default)
};

// S with SᵀS = Σ⁻¹ (S = L⁻¹, Σ = LLᵀ); throws std::invalid_argument if Σ is
// not positive definite.
Mat3 SqrtInformation(const Mat3& covariance);

namespace internal {

using Row3x18 = Eigen::Matrix<double, 3, 18>;
using Jac3x6 = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;

// Writes D·J (3×18) of one knot into its pose (lifted), ϖ and ϖ̇ blocks.
inline void WriteKnotJacobians(const Row3x18& DJ, const double* pose, double* j_pose, double* j_vel,
                               double* j_acc) {
  if (j_pose != nullptr) LiftPoseJacobian<3>(DJ.leftCols<6>(), pose, j_pose);
  if (j_vel != nullptr) Eigen::Map<Jac3x6>{j_vel} = DJ.middleCols<6>(6);
  if (j_acc != nullptr) Eigen::Map<Jac3x6>{j_acc} = DJ.rightCols<6>();
}

// Whether Ceres asks for any of the two knots' Jacobians (blocks 0–5: pose, ϖ, ϖ̇ of each).
inline bool NeedsKnotJacobians(double const* const* jacobians) {
  if (jacobians == nullptr) return false;
  for (int i = 0; i < 6; ++i) {
    if (jacobians[i] != nullptr) return true;
  }
  return false;
}

// The knots' bias blocks [b_a; b_g]: the residual reads b(τ) = (1 − s)·b_k + s·b_{k+1} through
// −S on three columns (first_col 0: the accelerometer's, 3: the gyro's); the others are zero.
inline void WriteBiasJacobians(const Mat3& S, double s, int first_col, double* j_b_k,
                               double* j_b_k1) {
  double* const j[2] = {j_b_k, j_b_k1};
  for (int i = 0; i < 2; ++i) {
    if (j[i] == nullptr) continue;
    Eigen::Map<Jac3x6> J{j[i]};
    J.setZero();
    J.middleCols<3>(first_col) = -(i == 0 ? 1.0 - s : s) * S;
  }
}

// e_g = S(ω_m + C_ir ϖ_ω(τ) − b_g(τ)).
class GyroResidual {
 public:
  GyroResidual(const Vec3& gyro, const Mat3& covariance, const ImuMounting& mounting);

  Vec3 Evaluate(const gp::KnotState& x, const Vec3& bg) const {
    const Vec3 w_imu = rotated_ ? Vec3(C_ir_ * x.velocity.tail<3>()) : Vec3(x.velocity.tail<3>());
    return sqrt_information_ * (gyro_ + w_imu - bg);
  }
  // D·M, D = S[0 … C_ir at ϖ_ω … 0]: rows 9–11 of M.
  template <typename Derived>
  Eigen::Matrix<double, 3, Derived::ColsAtCompileTime> Chain(
      const Eigen::MatrixBase<Derived>& M) const {
    return S_C_ir_ * M.template middleRows<3>(9);
  }
  const Mat3& sqrt_information() const { return sqrt_information_; }

 private:
  Vec3 gyro_;
  Mat3 sqrt_information_;
  Mat3 C_ir_;    // robot → IMU rotation
  Mat3 S_C_ir_;  // S·C_ir
  bool rotated_;
};

// e_a = S(f_m + C_ir[ϖ̇_v + C_rm C_mi g_i (− ϖ_ω×ϖ_v) − p×ϖ̇_ω − ϖ_ω×(ϖ_ω×p)] − b_a(τ)).
class AccelResidual {
 public:
  AccelResidual(const Vec3& accel, const Mat3& covariance, double gravity, AccelModel accel_model,
                const ImuMounting& mounting);

  // The state rows the residual reads (gp::StateRowBlock flags).
  static unsigned Rows(AccelModel accel_model, const ImuMounting& mounting);
  unsigned rows() const { return rows_; }

  // The parts of D at x(τ), C_mi that Chain and GravityJacobian read.
  struct Linearisation {
    Mat3 G;    // −(C C_mi g_i)^ on δφ
    Mat3 W;    // on ϖ_ω (exact model, lever arm)
    Mat3 Hww;  // ϖ_ω^ (exact model, on ϖ_v)
    Mat3 C;    // C_rm(τ)
    Vec3 g_m;  // C_mi g_i
  };
  // The residual; with `lin`, also D's parts.
  Vec3 Evaluate(const gp::KnotState& x, const Mat3& C_mi, const Vec3& ba, Linearisation* lin) const;
  // The ϖ̇_v at which the residual vanishes, the rest of x as given: e is affine in ϖ̇_v with
  // slope S·C_ir (D above), so ϖ̇_v = −C_ri S⁻¹ e(x with ϖ̇_v = 0). What the sample says the
  // linear acceleration is (a knot's initial guess, lio/imu_knot_prediction.h).
  Vec3 ZeroingLinearAcceleration(const gp::KnotState& x, const Mat3& C_mi, const Vec3& ba) const;
  // D·M (rows 3–5 δφ, 6–8 ϖ_v, 9–11 ϖ_ω, 12–14 ϖ̇_v, 15–17 ϖ̇_ω of M).
  template <typename Derived>
  Eigen::Matrix<double, 3, Derived::ColsAtCompileTime> Chain(
      const Linearisation& lin, const Eigen::MatrixBase<Derived>& M) const {
    const bool exact = accel_model_ == AccelModel::kSpecificForce;
    Eigen::Matrix<double, 3, Derived::ColsAtCompileTime> DM = M.template middleRows<3>(12);
    DM.noalias() += lin.G * M.template middleRows<3>(3);
    if (exact) DM.noalias() -= lin.Hww * M.template middleRows<3>(6);
    if (exact || lever_arm_nonzero_) DM.noalias() += lin.W * M.template middleRows<3>(9);
    if (lever_arm_nonzero_) DM.noalias() -= so3::Hat(lever_arm_) * M.template middleRows<3>(15);
    return S_C_ir_ * DM;
  }
  // ∂e_a/∂ψ for C_mi ← Exp(ψ)C_mi (3×3, before lifting).
  Mat3 GravityJacobian(const Linearisation& lin) const {
    return -S_C_ir_ * lin.C * so3::Hat(lin.g_m);
  }
  const Mat3& sqrt_information() const { return sqrt_information_; }

 private:
  Vec3 accel_;
  Mat3 sqrt_information_;
  Vec3 gravity_i_;
  AccelModel accel_model_;
  Mat3 C_ir_;    // robot → IMU rotation
  Mat3 S_C_ir_;  // S·C_ir
  bool rotated_;
  Vec3 lever_arm_;  // p
  bool lever_arm_nonzero_;
  unsigned rows_;
};

// The state at τ = stamp + δ for the time-offset factors (imu_gyro_time_offset.h): τ clamped to
// [t_k, t_{k+1}], the interpolation formed at τ, the `rows` of x(τ), of its knot Jacobians (with
// `knot_jacobians`) and of its rate ẋ(τ) (with `rate`), and the bias weight s(τ) with ds/dδ
// (1/(t_{k+1} − t_k) inside, 0 when clamped, where ẋ is zeroed too). `parameters`: the six knot
// blocks first.
struct TimeShiftedState {
  gp::KnotState x;
  gp::StateJacobian J_k, J_k1;
  gp::StateRate rate;
  double s = 0.0, ds_ddelta = 0.0;
};
void InterpolateShifted(const gp::SingerModel<6>& model, double t_k, double t_k1, double stamp,
                        double delta, unsigned rows, double const* const* parameters,
                        bool knot_jacobians, bool rate, TimeShiftedState* out);

}  // namespace internal
}  // namespace ctlio::imu
