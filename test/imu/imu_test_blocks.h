// Parameter storage shared by the IMU-measurement tests: the blocks of two GP knots, their biases
// and the gravity rotation C_mi, in the order ImuGyroMeasurement / ImuAccelMeasurement take them.
#pragma once

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <vector>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::testing {

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

}  // namespace ctlio::testing
