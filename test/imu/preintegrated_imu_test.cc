// Preintegration (SPEC §3) against motions whose end state is known in closed
// form. The scenarios are those GTSAM's ImuFactor tests use, re-derived here:
// every expected value below is computed from the motion, not copied.
#include "ctlio/factors/imu/preintegrated_imu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::imu {
namespace {

constexpr double kPi = 3.14159265358979323846;
const Vec3 kGravity(0.0, 0.0, -9.81);

double RotationError(const Mat3& A, const Mat3& B) { return so3::Log(A.transpose() * B).norm(); }

ImuNoise SmallNoise() {
  ImuNoise n;
  n.gyro_noise_density = 1.7e-4;
  n.accel_noise_density = 2e-3;
  return n;
}

// Constant body twist ν = [v_b; ω_b]: T_wb(t) = T_wb(0)·Exp(tν), so ṗ = C v_b,
// p̈ = C(ω × v_b) and the accelerometer reads f = ω × v_b − C(t)ᵀg.
struct ConstantTwist {
  SE3 T0;
  Vec3 v_body, w_body;
  SE3 Pose(double t) const {
    Vec6 xi;
    xi << v_body * t, w_body * t;
    return T0 * SE3::Exp(xi);
  }
  NavState State(double t) const {
    const SE3 T = Pose(t);
    return {T.rotation(), T.translation(), T.rotation() * v_body};
  }
  Vec3 SpecificForce(double t, const Vec3& g) const {
    return w_body.cross(v_body) - Pose(t).rotation().transpose() * g;
  }
};

TEST(PreintegratedImu, DoubleIntegralJacobianMatchesQuadrature) {
  for (const double angle : {0.0, 1e-6, 0.3, 0.49, 0.51, 2.0, 3.1}) {
    const Vec3 phi = angle * Vec3(0.3, -0.5, 0.8).normalized();
    // ∫₀¹(1−α)Exp(αφ)dα by composite Simpson with 2000 panels.
    const int n = 2000;
    Mat3 sum = Mat3::Zero();
    for (int i = 0; i <= n; ++i) {
      const double a = static_cast<double>(i) / n;
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      sum += w * (1.0 - a) * so3::Exp(a * phi);
    }
    sum /= 3.0 * n;
    EXPECT_LT((DoubleIntegralJacobian(phi) - sum).norm(), 1e-12) << "angle " << angle;
  }
}

// GTSAM "CheckCovariance": one 0.5 s sample, accel (0.1, 0, 0), gyro (π/100,
// 0, 0), σ_g = 0.5°/60 per √s, σ_a = 0.1/60. Expected: rotation σ_g²Δt,
// velocity σ_a²Δt, position σ_a²Δt³/4 (+ GTSAM's integration term 1e-4·Δt),
// position–velocity σ_a²Δt²/2.
TEST(PreintegratedImu, CheckCovarianceValues) {
  ImuNoise noise;
  noise.gyro_noise_density = 0.5 * kPi / 180.0 / 60.0;
  noise.accel_noise_density = 0.1 / 60.0;
  for (const double integration : {0.0, 1e-4}) {
    noise.integration_variance = integration;
    PreintegratedImu pim(Vec6::Zero(), noise);
    pim.Integrate(Vec3(0.1, 0.0, 0.0), Vec3(kPi / 100.0, 0.0, 0.0), 0.5);
    const Mat9& S = pim.covariance();
    const double rot = 1.0577e-8, vel = 1.38889e-6, cross = 3.47222e-7;
    const double pos = integration > 0.0 ? 5.00868e-5 : 8.68056e-8;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(S(i, i), rot, 2e-4 * rot);
      EXPECT_NEAR(S(3 + i, 3 + i), vel, 2e-4 * vel);
      EXPECT_NEAR(S(6 + i, 6 + i), pos, 2e-4 * pos);
      EXPECT_NEAR(S(3 + i, 6 + i), cross, 2e-4 * cross);
      EXPECT_NEAR(S(6 + i, 3 + i), cross, 2e-4 * cross);
    }
    // GTSAM's Euler step has no other entries. The exact step adds the
    // rotation of the sample within Δt: v–p cross terms ≈ σ_a²Δt²·θ/12 (θ =
    // 0.0157 rad, ~9.1e-10) and rotation–velocity terms ≈ σ_g²Δt²|a|/2.
    Mat9 off = S;
    for (int i = 0; i < 3; ++i) {
      off(i, i) = off(3 + i, 3 + i) = off(6 + i, 6 + i) = 0.0;
      off(3 + i, 6 + i) = off(6 + i, 3 + i) = 0.0;
    }
    EXPECT_LT(off.cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_GT(off.cwiseAbs().maxCoeff(), 5e-10);
  }
}

// Rotation at constant rate about a body axis n with the acceleration along the
// same axis: n stays fixed in the world, so C = C0·Exp(ωtn), p = ½αt²C0n,
// v = αtC0n. With the world gravity along C0n too, the accelerometer reading
// αn − Cᵀg is constant, and the exact-step integration is exact.
TEST(PreintegratedImu, ConstantRotationAccelerationAlongAxis) {
  const Vec3 n(0.0, 0.0, 1.0);
  const double w = 0.7, alpha = 1.3, dt = 0.01;
  const Vec3 gyro = w * n;
  const Vec3 accel = alpha * n - kGravity;  // C(t)ᵀg = g: rotation about g's axis
  PreintegratedImu pim(Vec6::Zero(), SmallNoise());
  for (int k = 0; k < 200; ++k) pim.Integrate(accel, gyro, dt);
  const double T = 2.0;
  const NavState x = pim.Predict(NavState{}, Vec6::Zero(), kGravity);
  EXPECT_LT(RotationError(x.C, so3::Exp(w * T * n)), 1e-12);
  EXPECT_LT((x.p - 0.5 * alpha * T * T * n).norm(), 1e-12);
  EXPECT_LT((x.v - alpha * T * n).norm(), 1e-12);
}

// GTSAM "PredictRotation": still platform spinning about the vertical at π/10
// rad/s for 1 s at 1 kHz → yaw π/10, no translation.
TEST(PreintegratedImu, PredictRotation) {
  PreintegratedImu pim(Vec6::Zero(), SmallNoise());
  for (int k = 0; k < 1000; ++k) pim.Integrate(-kGravity, Vec3(0.0, 0.0, kPi / 10.0), 1e-3);
  const NavState x = pim.Predict(NavState{}, Vec6::Zero(), kGravity);
  EXPECT_LT(RotationError(x.C, so3::Exp(Vec3(0.0, 0.0, kPi / 10.0))), 1e-12);
  EXPECT_LT(x.p.norm(), 1e-12);
  EXPECT_LT(x.v.norm(), 1e-12);
}

// GTSAM "PredictPositionAndVelocity": 1 m/s² along y for 1 s from rest → p =
// (0, 0.5, 0), v = (0, 1, 0). The readings carry an accelerometer bias that is
// NOT removed during integration (b̄ = 0) but by the first-order correction at
// prediction, which is exact for b_a when the rotation does not depend on it.
TEST(PreintegratedImu, PredictPositionAndVelocityWithAccelBiasCorrection) {
  const Vec3 ba(0.05, 0.1, -0.2);
  PreintegratedImu pim(Vec6::Zero(), SmallNoise());
  for (int k = 0; k < 1000; ++k)
    pim.Integrate(Vec3(0.0, 1.0, 0.0) - kGravity + ba, Vec3::Zero(), 1e-3);
  Vec6 bias;
  bias << ba, Vec3::Zero();
  const NavState x = pim.Predict(NavState{}, bias, kGravity);
  EXPECT_LT((x.p - Vec3(0.0, 0.5, 0.0)).norm(), 1e-12);
  EXPECT_LT((x.v - Vec3(0.0, 1.0, 0.0)).norm(), 1e-12);
  EXPECT_LT(RotationError(x.C, Mat3::Identity()), 1e-12);
  // Without the correction the bias integrates into a 10 cm error.
  const NavState raw = pim.Predict(NavState{}, Vec6::Zero(), kGravity);
  EXPECT_GT((raw.p - Vec3(0.0, 0.5, 0.0)).norm(), 0.1);
}

// Gyro bias enters nonlinearly: the first-order correction must leave an error
// that is quadratic in δb_g (halving δb divides it by ~4) and far below the
// uncorrected error.
TEST(PreintegratedImu, GyroBiasCorrectionIsSecondOrder) {
  const ConstantTwist motion{SE3(), Vec3(1.0, 0.2, -0.3), Vec3(0.3, -0.4, 0.5)};
  auto integrate = [&](const Vec6& bias_hat, const Vec6& bias_true) {
    PreintegratedImu pim(bias_hat, SmallNoise());
    const double dt = 5e-3;
    for (int k = 0; k < 200; ++k) {
      const double t = (k + 0.5) * dt;
      pim.Integrate(motion.SpecificForce(t, kGravity) + bias_true.head<3>(),
                    motion.w_body + bias_true.tail<3>(), dt);
    }
    return pim;
  };
  double previous = 0.0;
  for (const double scale : {0.02, 0.01}) {
    Vec6 b;
    b << 0.1 * scale, -0.2 * scale, 0.3 * scale, 0.5 * scale, -1.0 * scale, 0.7 * scale;
    const PreintegratedImu at_zero = integrate(Vec6::Zero(), b);
    const PreintegratedImu at_b = integrate(b, b);
    const double err = (at_zero.CorrectedPosition(b) - at_b.delta_position()).norm() +
                       (at_zero.CorrectedVelocity(b) - at_b.delta_velocity()).norm() +
                       RotationError(at_zero.CorrectedRotation(b), at_b.delta_rotation());
    const double raw = (at_zero.delta_position() - at_b.delta_position()).norm() +
                       (at_zero.delta_velocity() - at_b.delta_velocity()).norm();
    EXPECT_LT(err, 1e-2 * raw) << "scale " << scale;
    if (previous > 0.0) {
      EXPECT_GT(previous / err, 3.5);
      EXPECT_LT(previous / err, 4.5);
    }
    previous = err;
  }
}

// The bias Jacobians against central differences of the full re-integration.
TEST(PreintegratedImu, BiasJacobiansMatchReintegration) {
  const ConstantTwist motion{SE3(), Vec3(1.0, 0.2, -0.3), Vec3(0.6, -0.8, 1.0)};
  auto integrate = [&](const Vec6& bias_hat) {
    PreintegratedImu pim(bias_hat, SmallNoise());
    const double dt = 1e-3;
    for (int k = 0; k < 1000; ++k) {
      const double t = (k + 0.5) * dt;
      pim.Integrate(motion.SpecificForce(t, kGravity), motion.w_body, dt);
    }
    return pim;
  };
  const Vec6 b0 = Vec6::Zero();
  const PreintegratedImu pim = integrate(b0);
  const double h = 1e-5;
  for (int j = 0; j < 6; ++j) {
    Vec6 bp = b0, bm = b0;
    bp[j] += h;
    bm[j] -= h;
    const PreintegratedImu p = integrate(bp), m = integrate(bm);
    const Vec3 dphi = (so3::Log(pim.delta_rotation().transpose() * p.delta_rotation()) -
                       so3::Log(pim.delta_rotation().transpose() * m.delta_rotation())) /
                      (2 * h);
    const Vec3 dv = (p.delta_velocity() - m.delta_velocity()) / (2 * h);
    const Vec3 dp = (p.delta_position() - m.delta_position()) / (2 * h);
    const Mat96& J = pim.bias_jacobian();
    // Rotation Jacobian exact; v and p up to the O(Δt) terms of the linearised
    // step (relative ~1e-3 at 1 kHz on this 1 s, 1 rad/s motion).
    EXPECT_LT((dphi - J.block<3, 1>(0, j)).norm(), 1e-6 * (1.0 + dphi.norm())) << j;
    EXPECT_LT((dv - J.block<3, 1>(3, j)).norm(), 2e-3 * (1.0 + dv.norm())) << j;
    EXPECT_LT((dp - J.block<3, 1>(6, j)).norm(), 2e-3 * (1.0 + dp.norm())) << j;
  }
}

// A sensor mounted rotated (C_bs = flip about x plus a yaw) reports ω_s = C_bsᵀω_b,
// f_s = C_bsᵀf_b; with C_bs given, the deltas equal those of a body-mounted IMU
// (biases are sensor-frame quantities and get rotated too).
TEST(PreintegratedImu, SensorToBodyRotation) {
  const Mat3 C_bs = so3::Exp(Vec3(kPi, 0.0, 0.0)) * so3::Exp(Vec3(0.0, 0.0, 0.4));
  const ConstantTwist motion{SE3(), Vec3(0.5, 0.0, 0.1), Vec3(0.0, 0.0, kPi / 10.0)};
  Vec6 bias_s;
  bias_s << 0.01, -0.02, 0.03, 1e-3, 2e-3, -3e-3;
  Vec6 bias_b;
  bias_b << C_bs * bias_s.head<3>(), C_bs * bias_s.tail<3>();
  PreintegratedImu body(bias_b, SmallNoise());
  PreintegratedImu sensor(bias_s, SmallNoise(), C_bs);
  for (int k = 0; k < 500; ++k) {
    const double t = (k + 0.5) * 2e-3;
    const Vec3 f_b = motion.SpecificForce(t, kGravity) + bias_b.head<3>();
    const Vec3 w_b = motion.w_body + bias_b.tail<3>();
    body.Integrate(f_b, w_b, 2e-3);
    sensor.Integrate(C_bs.transpose() * f_b, C_bs.transpose() * w_b, 2e-3);
  }
  EXPECT_LT(RotationError(body.delta_rotation(), sensor.delta_rotation()), 1e-12);
  EXPECT_LT((body.delta_velocity() - sensor.delta_velocity()).norm(), 1e-12);
  EXPECT_LT((body.delta_position() - sensor.delta_position()).norm(), 1e-12);
  EXPECT_LT((body.covariance() - sensor.covariance()).norm(), 1e-12 * body.covariance().norm());
  // Bias Jacobians: d/db_s = d/db_b · C_bs.
  Mat96 expected = body.bias_jacobian();
  expected.leftCols<3>() = body.bias_jacobian().leftCols<3>() * C_bs;
  expected.rightCols<3>() = body.bias_jacobian().rightCols<3>() * C_bs;
  EXPECT_LT((expected - sensor.bias_jacobian()).norm(), 1e-12);
  // And the predicted pose is the analytic one (Vicon-free sanity check).
  const NavState x = sensor.Predict(motion.State(0.0), bias_s, kGravity);
  const NavState truth = motion.State(1.0);
  EXPECT_LT(RotationError(x.C, truth.C), 1e-6);
}

// Constant twist sampled at 1 kHz. Without gravity the readings are constant in
// the body frame and the exact step reproduces Exp(tν) to 1e-6 (in fact to
// round-off); with gravity the reading C(t)ᵀg turns within each sample and
// mid-sample readings leave an O(Δt²) error.
TEST(PreintegratedImu, ConstantTwistAt1kHzMatchesAnalyticPose) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const ConstantTwist motion{testing::RandomPose(rng, 3.0, 5.0),
                               testing::RandomVec6(rng, 2.0).head<3>(),
                               testing::RandomVec6(rng, 1.5).head<3>()};
    for (const bool with_gravity : {false, true}) {
      const Vec3 g = with_gravity ? kGravity : Vec3::Zero();
      PreintegratedImu pim(Vec6::Zero(), SmallNoise());
      for (int k = 0; k < 1000; ++k) {
        pim.Integrate(motion.SpecificForce((k + 0.5) * 1e-3, g), motion.w_body, 1e-3);
      }
      const NavState x = pim.Predict(motion.State(0.0), Vec6::Zero(), g);
      const NavState truth = motion.State(1.0);
      const double tol = with_gravity ? 1e-5 : 1e-6;
      EXPECT_LT(RotationError(x.C, truth.C), 1e-9);
      EXPECT_LT((x.p - truth.p).norm(), tol) << "gravity " << with_gravity;
      EXPECT_LT((x.v - truth.v).norm(), tol) << "gravity " << with_gravity;
      if (!with_gravity) {
        EXPECT_LT((x.p - truth.p).norm(), 1e-10);
      }
    }
  }
}

TEST(PreintegratedImu, RejectsBadInput) {
  PreintegratedImu pim(Vec6::Zero(), SmallNoise());
  EXPECT_THROW(pim.Integrate(Vec3::Zero(), Vec3::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(pim.Integrate(Vec3(NAN, 0, 0), Vec3::Zero(), 1e-3), std::invalid_argument);
  Mat3 not_rotation = Mat3::Identity();
  not_rotation(0, 0) = 2.0;
  EXPECT_THROW(PreintegratedImu(Vec6::Zero(), SmallNoise(), not_rotation), std::invalid_argument);
  EXPECT_THROW(PreintegratedImuFactor(pim, kGravity), std::invalid_argument);  // Δt = 0
}

// ---------------------------------------------------------------------------
// The cost function.

struct FactorFixture {
  PreintegratedImu pim{Vec6::Zero(), SmallNoise()};
  ConstantTwist motion;
  Vec6 bias_hat;
  Vec3 gravity;
  FactorFixture(std::mt19937& rng, double max_angle, const Vec3& g = kGravity) : gravity(g) {
    motion = {testing::RandomPose(rng, max_angle, 10.0), testing::RandomVec6(rng, 1.5).head<3>(),
              testing::RandomVec6(rng, 1.0).head<3>()};
    bias_hat = testing::RandomVec6(rng, 0.05);
    pim.Reset(bias_hat);
    for (int k = 0; k < 100; ++k) {
      pim.Integrate(motion.SpecificForce((k + 0.5) * 5e-3, gravity) + bias_hat.head<3>(),
                    motion.w_body + bias_hat.tail<3>(), 5e-3);
    }
  }
};

std::vector<double> Params(const NavState& x) {
  std::vector<double> p(7);
  PoseManifold::Store(SE3(x.C, x.p), p.data());
  return p;
}

TEST(PreintegratedImuFactor, ZeroResidualOnTheTrueMotion) {
  std::mt19937 rng(3);
  // Gravity-free constant twist: readings constant in the body frame, so the
  // preintegration is exact and the residual is round-off.
  FactorFixture f(rng, 3.0, Vec3::Zero());
  const PreintegratedImuFactor cost(f.pim, Vec3::Zero());
  const NavState xi = f.motion.State(0.0), xj = f.motion.State(0.5);
  std::vector<double> pi = Params(xi), pj = Params(xj);
  Vec3 vi = xi.v, vj = xj.v;
  Vec6 b = f.bias_hat;
  const double* params[] = {pi.data(), vi.data(), b.data(), pj.data(), vj.data()};
  Eigen::Matrix<double, 9, 1> r;
  ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-6) << r.transpose();
  // Moving the end pose by 1 mm makes it clearly non-zero.
  pj[0] += 1e-3;
  ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_GT(r.norm(), 1.0);
}

TEST(PreintegratedImuFactor, JacobiansMatchNumeric) {
  std::mt19937 rng(11);
  PoseManifold pose_manifold;
  for (int trial = 0; trial < 6; ++trial) {
    // Random, large-rotation (near π) and near-identity states; residuals
    // away from zero and biases away from b̄.
    const double max_angle = trial < 2 ? 1.0 : (trial < 4 ? 3.1 : 1e-6);
    FactorFixture f(rng, max_angle);
    const PreintegratedImuFactor cost(f.pim, kGravity);
    std::vector<double> pi = testing::PoseParameters(testing::RandomPose(rng, max_angle, 5.0));
    std::vector<double> pj = testing::PoseParameters(testing::RandomPose(rng, max_angle, 5.0));
    Vec3 vi = testing::RandomVec6(rng, 2.0).head<3>(), vj = testing::RandomVec6(rng, 2.0).head<3>();
    Vec6 b = f.bias_hat + testing::RandomVec6(rng, 0.05);
    EXPECT_TRUE(testing::JacobiansMatchNumeric(
        cost, {&pose_manifold, nullptr, nullptr, &pose_manifold, nullptr},
        {pi.data(), vi.data(), b.data(), pj.data(), vj.data()}, 1e-5))
        << "trial " << trial;
  }
}

}  // namespace
}  // namespace ctlio::imu
