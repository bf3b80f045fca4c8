// IMU as a measurement with the IMU away from the robot frame (imu_mounting.h): the readings
// of a rotated IMU on a lever arm, computed from the physics of its own trajectory, give zero
// residual; every Jacobian matches numeric differentiation with a non-zero lever arm, including
// near-singular rotations; the default mounting is the robot frame.
#include "ctlio/factors/imu/imu_mounting.h"

#include <gtest/gtest.h>

#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/imu/imu_measurement.h"
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

ImuMounting RandomMounting(std::mt19937& rng, double lever) {
  return ImuMounting::FromPose(testing::RandomPose(rng, 3.0, lever));
}

// A robot trajectory with acceleration and jerk along a fixed twist direction u (the SPEC §2
// interpolation is exact there, see imu_measurement_test.cc), and an IMU rigidly mounted at
// T_ri. The IMU's readings come from finite differences of the IMU's OWN map-frame position and
// attitude T_mi(t) = T_mr(t)·T_ri, so the lever-arm terms ω̇×p and ω×(ω×p) are never written
// here: zero residual proves the factor's kinematics.
TEST(ImuMounting, ZeroResidualForARotatedImuOnALeverArmFromPhysics) {
  std::mt19937 rng(11);
  const Mat3 cov = Mat3::Identity();
  for (int trial = 0; trial < 4; ++trial) {
    const SE3 Tk = testing::RandomPose(rng, 3.0, 5.0);
    const Vec6 u = testing::RandomVec6(rng, 1.0);
    const double a = 1.5, b = -2.0 + trial, c3 = 3.0;
    const Mat3 C_mi = testing::RandomPose(rng, 0.2, 0.0).rotation();
    const ImuMounting mounting = RandomMounting(rng, 0.4);
    ASSERT_GT(mounting.lever_arm.norm(), 0.01);
    const auto xi = [&](double t) -> Vec6 { return (a * t + b * t * t + c3 * t * t * t) * u; };
    const auto pose = [&](double t) { return SE3::Exp(xi(t)) * Tk; };  // T_rm
    const auto knot = [&](double t) {
      KnotState s;
      s.pose = pose(t);
      s.velocity = (a + 2 * b * t + 3 * c3 * t * t) * u;
      s.acceleration = (2 * b + 6 * c3 * t) * u;
      return s;
    };
    const double t_k = 0.0, t_k1 = 0.25, tau = 0.11, h = 1e-3;
    const auto imu_pose = [&](double t) { return pose(t).Inverse() * mounting.Pose(); };  // T_mi
    const auto position = [&](double t) { return imu_pose(t).translation(); };
    const auto attitude = [&](double t) { return imu_pose(t).rotation(); };
    const Vec3 p_ddot = (-position(tau + 2 * h) + 16 * position(tau + h) - 30 * position(tau) +
                         16 * position(tau - h) - position(tau - 2 * h)) /
                        (12 * h * h);
    const Mat3 C_dot = (-attitude(tau + 2 * h) + 8 * attitude(tau + h) - 8 * attitude(tau - h) +
                        attitude(tau - 2 * h)) /
                       (12 * h);
    const Mat3 C_m_imu = attitude(tau);
    const Vec3 omega_i = so3::Vee(C_m_imu.transpose() * C_dot);
    const Vec3 g_m = C_mi * Vec3(0, 0, -9.81);
    const Vec3 f_i = C_m_imu.transpose() * (p_ddot - g_m);
    const Vec6 b_k = testing::RandomVec6(rng, 0.1), b_k1 = testing::RandomVec6(rng, 0.1);
    const double s = (tau - t_k) / (t_k1 - t_k);
    const Vec6 bias = (1 - s) * b_k + s * b_k1;
    const Blocks blocks(knot(t_k), knot(t_k1), b_k, b_k1, C_mi);

    const ImuGyroMeasurement gyro(Wnoj(), t_k, t_k1, tau, omega_i + bias.tail<3>(), cov, mounting);
    EXPECT_LT(Evaluate(gyro, blocks.Gyro()).norm(), 1e-8) << "trial " << trial;
    const ImuAccelMeasurement exact(Wnoj(), t_k, t_k1, tau, f_i + bias.head<3>(), cov, 9.81,
                                    AccelModel::kSpecificForce, mounting);
    EXPECT_LT(Evaluate(exact, blocks.Accel()).norm(), 1e-6) << "trial " << trial;

    // Without the mounting the same readings are far off: the test has teeth.
    const ImuAccelMeasurement unmounted(Wnoj(), t_k, t_k1, tau, f_i + bias.head<3>(), cov, 9.81,
                                        AccelModel::kSpecificForce);
    EXPECT_GT(Evaluate(unmounted, blocks.Accel()).norm(), 0.1);
  }
}

// The lever-arm terms alone: a robot spinning about a fixed axis with angular acceleration,
// IMU frame = robot frame rotated, lever arm p. Against the textbook centripetal and tangential
// accelerations, ω×(ω×p) + ω̇×p, written directly.
TEST(ImuMounting, LeverArmAddsCentripetalAndTangentialAcceleration) {
  std::mt19937 rng(12);
  const Mat3 cov = Mat3::Identity();
  const ImuMounting mounting = RandomMounting(rng, 0.5);
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const double omega0 = 2.0, omega_dot = 1.5, t_k = 0.0, t_k1 = 0.1;
  // Pure rotation about the origin, ω(t) = (ω0 + ω̇ t)·axis: along a fixed direction, exact.
  const auto knot = [&](double t) {
    KnotState s;
    Vec6 xi = Vec6::Zero();
    xi.tail<3>() = -(omega0 * t + 0.5 * omega_dot * t * t) * axis;  // ϖ = −[v; ω]
    s.pose = SE3::Exp(xi);
    s.velocity.setZero();
    s.velocity.tail<3>() = -(omega0 + omega_dot * t) * axis;
    s.acceleration.setZero();
    s.acceleration.tail<3>() = -omega_dot * axis;
    return s;
  };
  const double tau = 0.04;
  const Blocks blocks(knot(t_k), knot(t_k1), Vec6::Zero(), Vec6::Zero(), Mat3::Identity());
  const Vec3 w = (omega0 + omega_dot * tau) * axis, w_dot = omega_dot * axis;
  const Mat3 C_rm = knot(tau).pose.rotation();
  const Vec3 p = mounting.lever_arm;
  const Vec3 f_r = w.cross(w.cross(p)) + w_dot.cross(p) - C_rm * Vec3(0, 0, -9.81);
  const Vec3 f_i = mounting.C_ri.transpose() * f_r;
  for (const AccelModel model : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
    const ImuAccelMeasurement accel(Wnoj(), t_k, t_k1, tau, f_i, cov, 9.81, model, mounting);
    EXPECT_LT(Evaluate(accel, blocks.Accel()).norm(), 1e-9);
  }
  const ImuGyroMeasurement gyro(Wnoj(), t_k, t_k1, tau, mounting.C_ri.transpose() * w, cov,
                                mounting);
  EXPECT_LT(Evaluate(gyro, blocks.Gyro()).norm(), 1e-12);
}

TEST(ImuMounting, DefaultMountingIsTheRobotFrame) {
  std::mt19937 rng(13);
  KnotState k, k1;
  k.pose = testing::RandomPose(rng, 2.0, 3.0);
  k1.pose = SE3::Exp(testing::RandomVec6(rng, 0.3)) * k.pose;
  k.velocity = testing::RandomVec6(rng, 2.0);
  k1.velocity = testing::RandomVec6(rng, 2.0);
  k.acceleration = testing::RandomVec6(rng, 3.0);
  k1.acceleration = testing::RandomVec6(rng, 3.0);
  const Blocks blocks(k, k1, testing::RandomVec6(rng, 0.1), testing::RandomVec6(rng, 0.1),
                      testing::RandomPose(rng, 0.2, 0.0).rotation());
  const Vec3 meas(0.3, -0.2, 9.7);
  const Mat3 cov = 1e-3 * Mat3::Identity();
  const ImuMounting identity = ImuMounting::FromPose(SE3());
  EXPECT_FALSE(identity.HasRotation());
  EXPECT_FALSE(identity.HasLeverArm());
  const ImuAccelMeasurement a(Wnoj(), 0.0, 0.1, 0.03, meas, cov, 9.81, AccelModel::kSpecificForce);
  const ImuAccelMeasurement b(Wnoj(), 0.0, 0.1, 0.03, meas, cov, 9.81, AccelModel::kSpecificForce,
                              identity);
  EXPECT_EQ(Evaluate(a, blocks.Accel()), Evaluate(b, blocks.Accel()));
}

// AccelResidual::ZeroingLinearAcceleration (the knots' initial guess, lio/imu_knot_prediction.h):
// at the ϖ̇_v it returns the residual vanishes, for a rotated IMU on a lever arm, a correlated
// covariance, both models and random states, and it moves with the measurement (one m/s² more
// along the IMU's x is C_ri·e_x less of ϖ̇_v).
TEST(ImuMounting, ZeroingLinearAccelerationZeroesTheResidual) {
  std::mt19937 rng(29);
  Mat3 cov;
  cov << 2e-3, 5e-4, -2e-4, 5e-4, 1e-3, 1e-4, -2e-4, 1e-4, 3e-3;
  for (int trial = 0; trial < 20; ++trial) {
    const ImuMounting mounting = trial == 0 ? ImuMounting() : RandomMounting(rng, 0.5);
    KnotState x;
    x.pose = testing::RandomPose(rng, 3.0, 5.0);
    x.velocity = testing::RandomVec6(rng, 2.0);
    x.acceleration = testing::RandomVec6(rng, 10.0);
    const Mat3 C_mi = testing::RandomPose(rng, 0.3, 0.0).rotation();
    const Vec3 ba = testing::RandomVec6(rng, 0.1).head<3>();
    const Vec3 meas = testing::RandomVec6(rng, 10.0).head<3>();
    for (const AccelModel model : {AccelModel::kSpecificForce, AccelModel::kBodyCentric}) {
      const internal::AccelResidual residual(meas, cov, 9.81, model, mounting);
      KnotState zeroed = x;
      zeroed.acceleration.head<3>() = residual.ZeroingLinearAcceleration(x, C_mi, ba);
      EXPECT_LT(residual.Evaluate(zeroed, C_mi, ba, nullptr).norm(), 1e-9) << trial;
      EXPECT_GT(residual.Evaluate(x, C_mi, ba, nullptr).norm(), 1.0) << trial;
      const internal::AccelResidual shifted(meas + Vec3::UnitX(), cov, 9.81, model, mounting);
      EXPECT_LT((shifted.ZeroingLinearAcceleration(x, C_mi, ba) - zeroed.acceleration.head<3>() +
                 mounting.C_ri.col(0))
                    .norm(),
                1e-9)
          << trial;
    }
  }
}

// Every Jacobian against GradientChecker with a rotated IMU on a 0.3–0.6 m lever arm: generic,
// large-rotation (near π) and near-identity knots, both models, WNOJ and Singer.
TEST(ImuMounting, JacobiansMatchNumericWithLeverArm) {
  std::mt19937 rng(14);
  const testing::ImuManifolds manifolds;
  const Mat3 A = Mat3::Random();
  const Mat3 cov = 1e-3 * (A * A.transpose() + Mat3::Identity());
  for (int trial = 0; trial < 6; ++trial) {
    const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
    ImuMounting mounting = RandomMounting(rng, 0.6);
    if (trial == 2) mounting.C_ri = so3::Exp(Vec3(0, 3.14159, 0));  // IMU mounted upside down
    const double t_k = 0.3, t_k1 = 0.4, tau = 0.3 + 0.1 * (trial + 0.5) / 6.0;
    const Vec3 meas = testing::RandomVec6(rng, 5.0).head<3>();
    for (const SingerModel<6>& model : {Wnoj(), Singer()}) {
      const ImuGyroMeasurement gyro(model, t_k, t_k1, tau, meas, cov, mounting);
      EXPECT_TRUE(testing::JacobiansMatchNumeric(gyro, manifolds.gyro, blocks.Gyro(), 1e-6))
          << "gyro trial " << trial;
      for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
        const ImuAccelMeasurement accel(model, t_k, t_k1, tau, meas, cov, 9.81, m, mounting);
        EXPECT_TRUE(testing::JacobiansMatchNumeric(accel, manifolds.accel, blocks.Accel(), 1e-6))
            << "accel trial " << trial << " model " << static_cast<int>(m);
      }
    }
  }
}

// The mountings of the multi-IMU pipeline at their singular points: the IMU rotation near π about
// a generic axis and near identity (1e-8 rad), a 0.3 m lever arm, the Singer prior with α·Δt → 0
// (α = 1e-6 over 0.1 s) and the interpolation time at a knot (s → 0).
TEST(ImuMounting, JacobiansMatchNumericAtSingularMountings) {
  std::mt19937 rng(15);
  const testing::ImuManifolds manifolds;
  const Mat3 cov = 1e-3 * Mat3::Identity();
  const Vec3 axis = Vec3(0.4, -0.7, 0.59).normalized();
  const SingerModel<6> tiny_alpha(Vec6::Constant(100.0), Vec6::Constant(1e-6));
  const Vec3 lever(0.3, 0.0, 0.0);
  for (const double angle : {M_PI - 1e-6, 1e-8}) {
    ImuMounting mounting;
    mounting.C_ri = so3::Exp(angle * axis);
    mounting.lever_arm = lever;
    for (int trial = 0; trial < 6; ++trial) {
      const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
      const double t_k = 0.3, t_k1 = 0.4;
      const double tau = trial == 0 ? t_k + 1e-9 : 0.3 + 0.1 * (trial + 0.5) / 6.0;
      const Vec3 meas = testing::RandomVec6(rng, 5.0).head<3>();
      for (const SingerModel<6>& model : {Singer(), tiny_alpha}) {
        const ImuGyroMeasurement gyro(model, t_k, t_k1, tau, meas, cov, mounting);
        EXPECT_TRUE(testing::JacobiansMatchNumeric(gyro, manifolds.gyro, blocks.Gyro(), 1e-6))
            << "gyro angle " << angle << " trial " << trial;
        const ImuAccelMeasurement accel(model, t_k, t_k1, tau, meas, cov, 9.81,
                                        AccelModel::kSpecificForce, mounting);
        EXPECT_TRUE(testing::JacobiansMatchNumeric(accel, manifolds.accel, blocks.Accel(), 1e-6))
            << "accel angle " << angle << " trial " << trial;
      }
    }
  }
}

}  // namespace
}  // namespace ctlio::imu
