// Measurement factors of factors/priors: PositionMeasurement on a pose block in both conventions
// (residual = the body's position minus the measured one, whitened) and LinearMeasurement on a
// vector block; Jacobians against the common numeric check at random states, rotations near π
// (large rotation) and at the identity / zero translation / 1e-9 rad (near-singular).
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/priors/linear_measurement.h"
#include "ctlio/factors/priors/position_measurement.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomPose;
const PoseManifold kPoseManifold;

Mat3 RandomSpd3(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = u(rng);
  return A * A.transpose() + 0.05 * Mat3::Identity();
}

// Poses that exercise every branch of Exp/Log and of the Jacobians: random, |φ| close to π,
// exactly the identity, a 1e-9 rad rotation with zero translation.
std::vector<SE3> TestPoses(std::mt19937& rng) {
  std::vector<SE3> poses;
  for (int i = 0; i < 5; ++i) poses.push_back(RandomPose(rng, 3.0, 10.0));
  for (int i = 0; i < 3; ++i) {
    const SE3 T = RandomPose(rng, 1.0, 10.0);
    const Vec3 axis = so3::Log(T.rotation()).normalized();
    poses.push_back(SE3(so3::Exp((3.14159265358979 - 1e-6 * i) * axis), T.translation()));
  }
  poses.push_back(SE3());
  poses.push_back(SE3(so3::Exp(Vec3(1e-9, -2e-9, 0.5e-9)), Vec3::Zero()));
  return poses;
}

TEST(PositionMeasurementTest, ResidualIsTheWhitenedPositionError) {
  std::mt19937 rng(21);
  for (const SE3& T : TestPoses(rng)) {
    const Mat3 cov = RandomSpd3(rng);
    const Vec3 measured = RandomPose(rng, 0.0, 5.0).translation();
    const Mat3 W = SqrtInformationFromCovariance<3>(cov);
    const std::vector<double> x = PoseParameters(T);
    const double* params[] = {x.data()};
    Vec3 r;
    // T as T_wb: the body is at r_wb.
    const PositionMeasurement world(measured, cov, PoseConvention::kWorldFromBody);
    ASSERT_TRUE(world.Evaluate(params, r.data(), nullptr));
    EXPECT_LT((r - W * (T.translation() - measured)).norm(), 1e-12 * (1.0 + r.norm()));
    // T as T_rm: the body is at the translation of T⁻¹, −C_rmᵀ r_rm.
    const PositionMeasurement body(measured, cov, PoseConvention::kBodyFromWorld);
    ASSERT_TRUE(body.Evaluate(params, r.data(), nullptr));
    const Vec3 p = -T.rotation().transpose() * T.translation();
    EXPECT_LT((r - W * (p - measured)).norm(), 1e-12 * (1.0 + r.norm()));
  }
}

TEST(PositionMeasurementTest, JacobiansMatchNumeric) {
  std::mt19937 rng(22);
  int checked = 0;
  for (const SE3& T : TestPoses(rng)) {
    const Mat3 cov = RandomSpd3(rng);
    // Measurements near and far from the pose: the Jacobians are exact, not small-error forms.
    for (const double offset : {0.0, 0.01, 20.0}) {
      const Vec3 measured = T.translation() + offset * Vec3(0.3, -0.8, 0.5);
      const std::vector<double> x = PoseParameters(T);
      for (const PoseConvention c :
           {PoseConvention::kWorldFromBody, PoseConvention::kBodyFromWorld}) {
        const PositionMeasurement f(measured, cov, c);
        EXPECT_TRUE(JacobiansMatchNumeric(f, {&kPoseManifold}, {x.data()}))
            << "angle " << so3::Log(T.rotation()).norm() << " offset " << offset << " convention "
            << static_cast<int>(c);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 60);
}

TEST(PositionMeasurementTest, RejectsABadCovariance) {
  EXPECT_THROW(PositionMeasurement(Vec3::Zero(), -Mat3::Identity(), PoseConvention::kWorldFromBody),
               std::invalid_argument);
  Mat3 nan = Mat3::Identity();
  nan(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(PositionMeasurement(Vec3::Zero(), nan, PoseConvention::kBodyFromWorld),
               std::invalid_argument);
}

TEST(LinearMeasurementTest, ResidualAndJacobians) {
  std::mt19937 rng(23);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::Matrix<double, 9, 1> x;
    for (int i = 0; i < 9; ++i) x[i] = trial == 0 ? 0.0 : 10.0 * n(rng);
    const Vec3 z(n(rng), n(rng), n(rng));
    const Mat3 cov = RandomSpd3(rng);
    // Leading: the position of a stacked [p; v; a] knot.
    std::unique_ptr<LinearMeasurement<3, 9>> f(LinearMeasurement<3, 9>::Leading(z, cov));
    const double* params[] = {x.data()};
    Vec3 r;
    ASSERT_TRUE(f->Evaluate(params, r.data(), nullptr));
    const Mat3 W = SqrtInformationFromCovariance<3>(cov);
    EXPECT_LT((r - W * (x.head<3>() - z)).norm(), 1e-12 * (1.0 + r.norm()));
    EXPECT_TRUE(JacobiansMatchNumeric(*f, {nullptr}, {x.data()})) << trial;
    // A general H.
    Eigen::Matrix<double, 3, 9> H;
    for (int i = 0; i < 27; ++i) H(i / 9, i % 9) = n(rng);
    const LinearMeasurement<3, 9> g(z, H, cov);
    ASSERT_TRUE(g.Evaluate(params, r.data(), nullptr));
    EXPECT_LT((r - W * (H * x - z)).norm(), 1e-12 * (1.0 + r.norm()));
    EXPECT_TRUE(JacobiansMatchNumeric(g, {nullptr}, {x.data()})) << trial;
  }
}

}  // namespace
}  // namespace ctlio
