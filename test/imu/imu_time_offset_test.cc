// IMU measurements with an estimated clock offset δ (imu_gyro_time_offset.h,
// imu_accel_time_offset.h): at δ they equal the fixed-time factors at τ = stamp + δ, they vanish
// on a trajectory that follows the model when δ is the true offset, and every Jacobian — ∂e/∂δ
// through the interpolation's time derivative included — matches numeric differentiation.
#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/imu/imu_accel_time_offset.h"
#include "ctlio/factors/imu/imu_gyro_time_offset.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "imu/imu_test_blocks.h"

namespace ctlio::imu {
namespace {

using ::ctlio::testing::Blocks;
using ::ctlio::testing::Singer;
using ::ctlio::testing::Wnoj;
using gp::SingerModel;

// The Blocks' parameters followed by δ.
std::vector<const double*> With(std::vector<const double*> p, const double* delta) {
  p.push_back(delta);
  return p;
}

ImuMounting TiltedLeverArm() {
  ImuMounting m;
  m.C_ri = so3::Exp(Vec3(0.3, -0.7, 1.1));
  m.lever_arm = Vec3(0.12, -0.05, 0.3);
  return m;
}

// α·Δt → 0 on every axis (the WNOJ limit of the Singer prior, and a nearly-WNOJ α) besides the
// Newer College prior.
std::vector<SingerModel<6>> Models() {
  return {Wnoj(), Singer(), SingerModel<6>(Vec6::Constant(2.0), Vec6::Constant(1e-7))};
}

TEST(ImuTimeOffset, EqualsFixedTimeFactorAtTheShiftedTime) {
  std::mt19937 rng(8);
  const Mat3 cov = 2e-3 * Mat3::Identity();
  for (int trial = 0; trial < 6; ++trial) {
    const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
    const double t_k = 0.3, t_k1 = 0.4, stamp = 0.337, delta = -0.011;
    const Vec3 meas = testing::RandomVec6(rng, 5.0).head<3>();
    for (const ImuMounting& mounting : {ImuMounting(), TiltedLeverArm()}) {
      for (const SingerModel<6>& model : Models()) {
        const ImuGyroMeasurementWithTimeOffset g(model, t_k, t_k1, stamp, meas, cov, mounting);
        const ImuGyroMeasurement g0(model, t_k, t_k1, stamp + delta, meas, cov, mounting);
        EXPECT_LT((testing::Evaluate(g, With(blocks.Gyro(), &delta)) -
                   testing::Evaluate(g0, blocks.Gyro()))
                      .norm(),
                  1e-9);
        for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
          const ImuAccelMeasurementWithTimeOffset a(model, t_k, t_k1, stamp, meas, cov, 9.81, m,
                                                    mounting);
          const ImuAccelMeasurement a0(model, t_k, t_k1, stamp + delta, meas, cov, 9.81, m,
                                       mounting);
          EXPECT_LT((testing::Evaluate(a, With(blocks.Accel(), &delta)) -
                     testing::Evaluate(a0, blocks.Accel()))
                        .norm(),
                    1e-9);
        }
      }
    }
  }
}

TEST(ImuTimeOffset, JacobiansMatchNumeric) {
  std::mt19937 rng(5);
  const testing::ImuManifolds manifolds;
  std::vector<const ceres::Manifold*> gyro_m = manifolds.gyro, accel_m = manifolds.accel;
  gyro_m.push_back(nullptr);
  accel_m.push_back(nullptr);
  Mat3 A = Mat3::Random();
  const Mat3 cov = 1e-3 * (A * A.transpose() + Mat3::Identity());
  // trials: generic, |φ| near π, near identity with tiny motion (testing::JacobianCheckBlocks).
  for (int trial = 0; trial < 6; ++trial) {
    const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
    const double t_k = 0.3, t_k1 = 0.4;
    const double stamp = 0.3 + 0.1 * (trial + 0.5) / 6.0;
    const double delta_ms = (trial % 2 == 0 ? 1.0 : -1.0) * 4.0;  // τ stays inside
    const Vec3 meas = testing::RandomVec6(rng, 5.0).head<3>();
    for (const ImuMounting& mounting : {ImuMounting(), TiltedLeverArm()}) {
      int model_index = 0;
      for (const SingerModel<6>& model : Models()) {
        ++model_index;
        const ImuGyroMeasurementWithTimeOffset gyro(model, t_k, t_k1, stamp, meas, cov, mounting);
        EXPECT_TRUE(testing::JacobiansMatchNumeric(testing::DeltaInMilliseconds(gyro), gyro_m,
                                                   With(blocks.Gyro(), &delta_ms), 1e-6))
            << "gyro trial " << trial << " prior " << model_index;
        for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
          const ImuAccelMeasurementWithTimeOffset accel(model, t_k, t_k1, stamp, meas, cov, 9.81, m,
                                                        mounting);
          EXPECT_TRUE(testing::JacobiansMatchNumeric(testing::DeltaInMilliseconds(accel), accel_m,
                                                     With(blocks.Accel(), &delta_ms), 1e-6))
              << "accel trial " << trial << " model " << static_cast<int>(m) << " prior "
              << model_index;
        }
      }
    }
  }
}

// Constant body twist ϖ with biases b_k, b_k1: the IMU reads the truth at τ = t + δ_true but
// stamps it t. At δ = δ_true the residual vanishes; at δ = 0 it does not.
TEST(ImuTimeOffset, ZeroResidualAtTheTrueOffset) {
  std::mt19937 rng(3);
  const Mat3 cov = 1e-4 * Mat3::Identity();
  const double t_k = 1.0, t_k1 = 1.1, delta_true = 0.013;
  for (int trial = 0; trial < 4; ++trial) {
    const SE3 T0 = testing::RandomPose(rng, 3.0, 5.0);
    Vec6 w = testing::RandomVec6(rng, 2.0);
    w.head<3>() = 1.7 * w.tail<3>();  // screw motion: ω×v = 0, both accelerometer models exact
    const Mat3 C_mi = testing::RandomPose(rng, 0.3, 0.0).rotation();
    const Vec6 b_k = testing::RandomVec6(rng, 0.1), b_k1 = testing::RandomVec6(rng, 0.1);
    gp::KnotState k, k1;
    k.pose = SE3::Exp(t_k * w) * T0;
    k.velocity = w;
    k1.pose = SE3::Exp(t_k1 * w) * T0;
    k1.velocity = w;
    const Blocks blocks(k, k1, b_k, b_k1, C_mi);
    const double stamp = 1.04, tau = stamp + delta_true, s = (tau - t_k) / (t_k1 - t_k);
    const Vec3 gyro = -w.tail<3>() + (1 - s) * b_k.tail<3>() + s * b_k1.tail<3>();
    const Vec3 accel = -(SE3::Exp(tau * w) * T0).rotation() * C_mi * Vec3(0, 0, -9.81) +
                       (1 - s) * b_k.head<3>() + s * b_k1.head<3>();
    const double zero = 0.0;
    for (const SingerModel<6>& model : {Wnoj(), Singer()}) {
      const ImuGyroMeasurementWithTimeOffset g(model, t_k, t_k1, stamp, gyro, cov);
      EXPECT_LT(testing::Evaluate(g, With(blocks.Gyro(), &delta_true)).norm(), 1e-8);
      for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
        const ImuAccelMeasurementWithTimeOffset a(model, t_k, t_k1, stamp, accel, cov, 9.81, m);
        EXPECT_LT(testing::Evaluate(a, With(blocks.Accel(), &delta_true)).norm(), 1e-8);
        EXPECT_GT(testing::Evaluate(a, With(blocks.Accel(), &zero)).norm(), 1e-3);
      }
    }
  }
}

// Outside [t_k, t_{k+1}] the state is the end's and ∂e/∂δ = 0 (imu_gyro_time_offset.h).
TEST(ImuTimeOffset, ClampsToTheInterval) {
  std::mt19937 rng(11);
  const Blocks blocks = testing::JacobianCheckBlocks(rng, 0);
  const Mat3 cov = Mat3::Identity();
  const ImuGyroMeasurementWithTimeOffset g(Singer(), 0.3, 0.4, 0.395, Vec3::Zero(), cov);
  const ImuGyroMeasurement end(Singer(), 0.3, 0.4, 0.4, Vec3::Zero(), cov);
  const double delta = 0.02;
  const auto p = With(blocks.Gyro(), &delta);
  Vec3 r;
  double jd[3];
  double* jac[9] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, jd};
  ASSERT_TRUE(g.Evaluate(p.data(), r.data(), jac));
  EXPECT_LT((r - testing::Evaluate(end, blocks.Gyro())).norm(), 1e-12);
  EXPECT_EQ(Eigen::Map<Vec3>(jd), Vec3::Zero());
  EXPECT_ANY_THROW(ImuGyroMeasurementWithTimeOffset(Wnoj(), 0.1, 0.1, 0.1, Vec3::Zero(), cov));
}

}  // namespace
}  // namespace ctlio::imu
