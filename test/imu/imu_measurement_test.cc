// IMU as a measurement (SPEC §3): zero residual on trajectories that follow
// each model exactly, the size of the ω×v term the paper's model leaves out,
// and every Jacobian against numeric differentiation.
#include "ctlio/factors/imu/imu_measurement.h"

#include <gtest/gtest.h>

#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "imu/imu_test_blocks.h"

namespace ctlio::imu {
namespace {

using gp::KnotState;
using gp::SingerModel;

using ::ctlio::testing::Singer;
using ::ctlio::testing::Wnoj;

using ::ctlio::testing::Blocks;
using ::ctlio::testing::Evaluate;

// Constant body twist: T_rm(t) = Exp(tϖ)T_0, ϖ̇ = 0, so the interpolation
// between knots on it is exact for every Singer α. The physical IMU reads
// ω = −ϖ_ω and f = ω×v_b − C_rm g_m (v_b = −ϖ_v), computed here from the
// physics, not from the residual.
struct ConstantTwistCase {
  SE3 T0;
  Vec6 w;  // ϖ
  Mat3 C_mi;
  Vec6 b_k, b_k1;
  KnotState Knot(double t) const {
    KnotState s;
    s.pose = SE3::Exp(t * w) * T0;
    s.velocity = w;
    return s;
  }
  Vec3 Gyro(double s) const { return -w.tail<3>() + (1 - s) * b_k.tail<3>() + s * b_k1.tail<3>(); }
  Vec3 Accel(double t, double s) const {
    const Vec3 v_b = -w.head<3>(), omega = -w.tail<3>();
    const Mat3 C_rm = Knot(t).pose.rotation();
    return omega.cross(v_b) - C_rm * C_mi * Vec3(0, 0, -9.81) + (1 - s) * b_k.head<3>() +
           s * b_k1.head<3>();
  }
};

ConstantTwistCase RandomTwist(std::mt19937& rng, bool screw) {
  ConstantTwistCase c;
  c.T0 = testing::RandomPose(rng, 3.0, 5.0);
  c.w = testing::RandomVec6(rng, 2.0);
  if (screw) c.w.head<3>() = 1.7 * c.w.tail<3>();  // v ∥ ω: ω×v = 0
  c.C_mi = testing::RandomPose(rng, 0.3, 0.0).rotation();
  c.b_k = testing::RandomVec6(rng, 0.1);
  c.b_k1 = testing::RandomVec6(rng, 0.1);
  return c;
}

TEST(ImuMeasurement, ZeroResidualOnScrewMotionForBothModels) {
  std::mt19937 rng(1);
  const Mat3 cov = 1e-4 * Mat3::Identity();
  for (int trial = 0; trial < 4; ++trial) {
    const ConstantTwistCase c = RandomTwist(rng, /*screw=*/true);
    const double t_k = 1.0, t_k1 = 1.1;
    const Blocks blocks(c.Knot(t_k), c.Knot(t_k1), c.b_k, c.b_k1, c.C_mi);
    for (const SingerModel<6>& model : {Wnoj(), Singer()}) {
      for (const double tau : {1.0, 1.037, 1.1}) {
        const double s = (tau - t_k) / (t_k1 - t_k);
        const ImuGyroMeasurement gyro(model, t_k, t_k1, tau, c.Gyro(s), cov);
        EXPECT_LT(Evaluate(gyro, blocks.Gyro()).norm(), 1e-8);
        for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
          const ImuAccelMeasurement accel(model, t_k, t_k1, tau, c.Accel(tau, s), cov, 9.81, m);
          EXPECT_LT(Evaluate(accel, blocks.Accel()).norm(), 1e-8);
        }
      }
    }
  }
}

// With ω×v ≠ 0 the exact model still gives zero; the paper's model is off by
// exactly S·(ω×v_b), the centripetal term it leaves out.
TEST(ImuMeasurement, BodyCentricModelMissesExactlyOmegaCrossV) {
  std::mt19937 rng(2);
  const Mat3 cov = Vec3(1e-4, 2e-4, 3e-4).asDiagonal();
  const Mat3 S = SqrtInformation(cov);
  for (int trial = 0; trial < 4; ++trial) {
    const ConstantTwistCase c = RandomTwist(rng, /*screw=*/false);
    const double t_k = 0.0, t_k1 = 0.2, tau = 0.13, s = tau / t_k1;
    const Blocks blocks(c.Knot(t_k), c.Knot(t_k1), c.b_k, c.b_k1, c.C_mi);
    const Vec3 f = c.Accel(tau, s);
    const ImuAccelMeasurement exact(Singer(), t_k, t_k1, tau, f, cov, 9.81,
                                    AccelModel::kSpecificForce);
    const ImuAccelMeasurement paper(Singer(), t_k, t_k1, tau, f, cov, 9.81,
                                    AccelModel::kBodyCentric);
    EXPECT_LT(Evaluate(exact, blocks.Accel()).norm(), 1e-8);
    const Vec3 omega_cross_v = (-c.w.tail<3>()).cross(-c.w.head<3>());
    EXPECT_GT(omega_cross_v.norm(), 0.1);
    EXPECT_LT((Evaluate(paper, blocks.Accel()) - S * omega_cross_v).norm(), 1e-8);
    // The default model is the exact one (the paper's is chosen explicitly).
    const ImuAccelMeasurement by_default(Singer(), t_k, t_k1, tau, f, cov);
    EXPECT_LT(Evaluate(by_default, blocks.Accel()).norm(), 1e-8);
  }
}

// A trajectory with acceleration and jerk along a fixed twist direction u:
// ξ(t) = (a t + b t² + c t³)·u local to knot k, T_rm(t) = Exp(ξ(t))T_k. WNOJ
// interpolation reproduces the cubic, and along a fixed u the SPEC §2 formula
// ϖ̇ = J(ξ)(ξ̈ + ½ξ̇^⋏ϖ) is exact (ξ̇^⋏ϖ = 0, J(ξ)u = u). (For a general cubic
// ξ(t) that formula is only first order in ξ: with knot states formed by it and
// |ξ| ≈ 0.15 the residual was ~1e-3 m/s², a property of the GP state, not of
// this factor.) The IMU
// readings are computed from the physical motion by finite differences of the
// map-frame position and attitude, independent of the ϖ conventions, so this
// checks the sign conventions end to end; u has ω×v ≠ 0.
TEST(ImuMeasurement, ZeroResidualOnAcceleratingTrajectoryFromPhysics) {
  std::mt19937 rng(3);
  const Mat3 cov = Mat3::Identity();
  for (int trial = 0; trial < 3; ++trial) {
    const SE3 Tk = testing::RandomPose(rng, 3.0, 5.0);
    const Vec6 u = testing::RandomVec6(rng, 1.0);
    const double a = 1.5, b = -2.0 + trial, c3 = 3.0;
    const Mat3 C_mi = testing::RandomPose(rng, 0.2, 0.0).rotation();
    const auto xi = [&](double t) -> Vec6 { return (a * t + b * t * t + c3 * t * t * t) * u; };
    const auto pose = [&](double t) { return SE3::Exp(xi(t)) * Tk; };
    const auto knot = [&](double t) {
      KnotState s;
      s.pose = pose(t);
      s.velocity = (a + 2 * b * t + 3 * c3 * t * t) * u;
      s.acceleration = (2 * b + 6 * c3 * t) * u;
      return s;
    };
    const double t_k = 0.0, t_k1 = 0.25, tau = 0.09, h = 1e-3;
    // Physics at τ: p = position of the robot in the map, C_mr its attitude.
    const auto position = [&](double t) { return pose(t).Inverse().translation(); };
    const auto attitude = [&](double t) { return pose(t).Inverse().rotation(); };
    const Vec3 p_dot = (-position(tau + 2 * h) + 8 * position(tau + h) - 8 * position(tau - h) +
                        position(tau - 2 * h)) /
                       (12 * h);
    const Vec3 p_ddot = (-position(tau + 2 * h) + 16 * position(tau + h) - 30 * position(tau) +
                         16 * position(tau - h) - position(tau - 2 * h)) /
                        (12 * h * h);
    const Mat3 C_dot = (-attitude(tau + 2 * h) + 8 * attitude(tau + h) - 8 * attitude(tau - h) +
                        attitude(tau - 2 * h)) /
                       (12 * h);
    const Mat3 C_mr = attitude(tau);
    const Vec3 omega = so3::Vee(C_mr.transpose() * C_dot);  // Ċ_mr = C_mr ω^
    const Vec3 v_b = C_mr.transpose() * p_dot;
    const Vec3 g_m = C_mi * Vec3(0, 0, -9.81);
    const Vec3 f = C_mr.transpose() * (p_ddot - g_m);
    const Blocks blocks(knot(t_k), knot(t_k1), Vec6::Zero(), Vec6::Zero(), C_mi);

    const ImuGyroMeasurement gyro(Wnoj(), t_k, t_k1, tau, omega, cov);
    EXPECT_LT(Evaluate(gyro, blocks.Gyro()).norm(), 1e-8);
    const ImuAccelMeasurement exact(Wnoj(), t_k, t_k1, tau, f, cov, 9.81,
                                    AccelModel::kSpecificForce);
    EXPECT_LT(Evaluate(exact, blocks.Accel()).norm(), 1e-7);
    const ImuAccelMeasurement paper(Wnoj(), t_k, t_k1, tau, f, cov, 9.81, AccelModel::kBodyCentric);
    EXPECT_LT((Evaluate(paper, blocks.Accel()) - omega.cross(v_b)).norm(), 1e-7);
    EXPECT_GT(omega.cross(v_b).norm(), 0.05);
  }
}

// Every Jacobian against GradientChecker, at random, large-rotation (near π)
// and near-identity knots, with random ϖ, ϖ̇, biases and C_mi.
TEST(ImuMeasurement, JacobiansMatchNumeric) {
  std::mt19937 rng(4);
  const testing::ImuManifolds manifolds;
  Mat3 A = Mat3::Random();
  const Mat3 cov = 1e-3 * (A * A.transpose() + Mat3::Identity());
  for (int trial = 0; trial < 6; ++trial) {
    const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
    const double t_k = 0.3, t_k1 = 0.4, tau = 0.3 + 0.1 * (trial + 0.5) / 6.0;
    const Vec3 meas = testing::RandomVec6(rng, 5.0).head<3>();
    for (const SingerModel<6>& model : {Wnoj(), Singer()}) {
      const ImuGyroMeasurement gyro(model, t_k, t_k1, tau, meas, cov);
      EXPECT_TRUE(testing::JacobiansMatchNumeric(gyro, manifolds.gyro, blocks.Gyro(), 1e-6))
          << "gyro trial " << trial;
      for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
        const ImuAccelMeasurement accel(model, t_k, t_k1, tau, meas, cov, 9.81, m);
        EXPECT_TRUE(testing::JacobiansMatchNumeric(accel, manifolds.accel, blocks.Accel(), 1e-6))
            << "accel trial " << trial << " model " << static_cast<int>(m);
      }
    }
  }
}

TEST(ImuMeasurement, RejectsBadArguments) {
  EXPECT_THROW(ImuGyroMeasurement(Wnoj(), 0.0, 0.1, 0.05, Vec3::Zero(), -Mat3::Identity()),
               std::invalid_argument);
  EXPECT_ANY_THROW(ImuGyroMeasurement(Wnoj(), 0.0, 0.1, 0.2, Vec3::Zero(), Mat3::Identity()));
  EXPECT_ANY_THROW(ImuAccelMeasurement(Wnoj(), 0.1, 0.1, 0.1, Vec3::Zero(), Mat3::Identity()));
}

}  // namespace
}  // namespace ctlio::imu
