// Shared by the IMU-measurement tests: the priors, and the blocks of two GP knots, their biases
// and the gravity rotation C_mi, in the order ImuGyroMeasurement / ImuAccelMeasurement take them.
#pragma once

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::testing {

// The two priors the IMU tests run every check under: WNOJ with Qc = 1, and a Singer prior with
// the Newer College α on rotation (SPEC §4).
inline gp::SingerModel<6> Wnoj() { return gp::SingerModel<6>::Wnoj(Vec6::Constant(1.0)); }
inline gp::SingerModel<6> Singer() {
  Vec6 qc, alpha;
  qc << 5000, 5000, 5000, 500, 500, 500;
  alpha << 0.5, 0.5, 0.5, 100, 100, 100;
  return gp::SingerModel<6>(qc, alpha);
}

// The manifolds of the factors' parameter blocks, in Blocks' order: two knots (pose on SE(3),
// velocity, acceleration), two bias blocks, and for the accelerometer the gravity rotation C_mi.
struct ImuManifolds {
  PoseManifold pose;
  RotationManifold rotation;
  std::vector<const ceres::Manifold*> gyro = {&pose,   nullptr, nullptr, &pose,
                                              nullptr, nullptr, nullptr, nullptr};
  std::vector<const ceres::Manifold*> accel = {&pose,   nullptr, nullptr, &pose,    nullptr,
                                               nullptr, nullptr, nullptr, &rotation};
  ImuManifolds() = default;
  ImuManifolds(const ImuManifolds&) = delete;  // the vectors point into this object
  ImuManifolds& operator=(const ImuManifolds&) = delete;
};

struct Blocks {
  double pose_k[7], vel_k[6], acc_k[6], pose_k1[7], vel_k1[6], acc_k1[6], b_k[6], b_k1[6], q_mi[4];
  Blocks(const gp::KnotState& k, const gp::KnotState& k1, const Vec6& bk, const Vec6& bk1,
         const Mat3& C_mi) {
    PoseManifold::Store(k.pose, pose_k);
    PoseManifold::Store(k1.pose, pose_k1);
    Eigen::Map<Vec6>{vel_k} = k.velocity;
    Eigen::Map<Vec6>{acc_k} = k.acceleration;
    Eigen::Map<Vec6>{vel_k1} = k1.velocity;
    Eigen::Map<Vec6>{acc_k1} = k1.acceleration;
    Eigen::Map<Vec6>{b_k} = bk;
    Eigen::Map<Vec6>{b_k1} = bk1;
    RotationManifold::Store(C_mi, q_mi);
  }
  std::vector<const double*> Gyro() const {
    return {pose_k, vel_k, acc_k, pose_k1, vel_k1, acc_k1, b_k, b_k1};
  }
  std::vector<const double*> Accel() const {
    return {pose_k, vel_k, acc_k, pose_k1, vel_k1, acc_k1, b_k, b_k1, q_mi};
  }
};

// The residual of `cost` at `params` (3 rows), without Jacobians.
inline Vec3 Evaluate(const ceres::CostFunction& cost, const std::vector<const double*>& params) {
  Vec3 r;
  EXPECT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  return r;
}

// A time-offset factor with δ in milliseconds (its last block; Jacobian column scaled by 1e-3). The
// gradient check's Ridders differences start at a step of 1e-3·max(|x|, 1) in the block's own units
// (common/gradient_check.h): 1 ms on a block in seconds, over which the interpolated acceleration
// of these random knots is far from its Taylor polynomial, so the extrapolation settles at ~1e-5
// (a central difference at 1e-7 s agrees with the analytic ∂e/∂δ to ~4e-10 relative). In
// milliseconds the first step is 1 µs.
class DeltaInMilliseconds final : public ceres::CostFunction {
 public:
  explicit DeltaInMilliseconds(const ceres::CostFunction& cost) : cost_(cost) {
    set_num_residuals(cost.num_residuals());
    *mutable_parameter_block_sizes() = cost.parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = static_cast<int>(parameter_block_sizes().size());
    std::vector<const double*> p(parameters, parameters + n);
    const double delta_s = 1e-3 * parameters[n - 1][0];
    p[n - 1] = &delta_s;
    if (!cost_.Evaluate(p.data(), residuals, jacobians)) return false;
    if (jacobians != nullptr && jacobians[n - 1] != nullptr) {
      for (int r = 0; r < num_residuals(); ++r) jacobians[n - 1][r] *= 1e-3;
    }
    return true;
  }

 private:
  const ceres::CostFunction& cost_;
};

// Knots for the Jacobian checks of trial 0–5: generic rotations (0, 1), |φ| near π (2, 3; trial 3
// also turns by 3 rad between the knots), near-identity with tiny motion (4, 5); random ϖ, ϖ̇,
// biases and C_mi.
inline Blocks JacobianCheckBlocks(std::mt19937& rng, int trial) {
  const double angle = trial < 2 ? 1.0 : (trial < 4 ? 3.1 : 1e-7);
  const double scale = trial < 4 ? 1.0 : 1e-6;
  gp::KnotState k, k1;
  k.pose = RandomPose(rng, angle, 5.0);
  k1.pose = SE3::Exp(RandomVec6(rng, 0.5 * scale)) * k.pose;
  if (trial == 3) k1.pose = SE3(so3::Exp(Vec3(0, 0, 3.0)), Vec3(1, 2, 3)) * k.pose;
  k.velocity = RandomVec6(rng, 2.0);
  k1.velocity = RandomVec6(rng, 2.0);
  k.acceleration = RandomVec6(rng, 3.0);
  k1.acceleration = RandomVec6(rng, 3.0);
  const Vec6 b_k = RandomVec6(rng, 0.1);
  const Vec6 b_k1 = RandomVec6(rng, 0.1);
  return Blocks(k, k1, b_k, b_k1, RandomPose(rng, 2.0, 0.0).rotation());
}

}  // namespace ctlio::testing
