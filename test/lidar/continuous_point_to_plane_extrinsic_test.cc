// ContinuousPointToPlaneExtrinsic (online lidar–IMU calibration): its residual is
// ContinuousPointToPlane's at the robot-frame point T_rl·q_l, and its Jacobians onto both knots
// and the extrinsic T_rl match numeric differentiation at random states, near the identity
// (knots and extrinsic), with rotations near π (knot and extrinsic), with α·Δt → 0, and through a
// SharedPoseInterpolation on its prepared path.
#include "ctlio/factors/lidar/continuous_point_to_plane_extrinsic.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;
using testing::RandomVec6;

Vec3 RandomPoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return 20.0 * Vec3(u(rng), u(rng), u(rng));
}

gp::SingerModel<6> Model(double alpha) {
  Vec6 qc;
  qc << 5000, 5000, 5000, 500, 500, 500;
  return gp::SingerModel<6>(qc, Vec6::Constant(alpha));
}

// The seven blocks: knots k, k+1 and T_rl.
struct State {
  std::vector<double> pose_k, pose_k1, extrinsic;
  Vec6 w_k, dw_k, w_k1, dw_k1;
  std::vector<const double*> Params() const {
    return {pose_k.data(), w_k.data(),   dw_k.data(),     pose_k1.data(),
            w_k1.data(),   dw_k1.data(), extrinsic.data()};
  }
};

State RandomState(std::mt19937& rng, double max_angle, double max_step, double velocity_scale,
                  double extrinsic_angle, double extrinsic_translation) {
  State s;
  const SE3 T_k = RandomPose(rng, max_angle, 10.0);
  s.pose_k = PoseParameters(T_k);
  s.pose_k1 = PoseParameters(RandomPose(rng, max_step, max_step) * T_k);
  s.w_k = RandomVec6(rng, velocity_scale);
  s.dw_k = RandomVec6(rng, 5.0 * velocity_scale);
  s.w_k1 = RandomVec6(rng, velocity_scale);
  s.dw_k1 = RandomVec6(rng, 5.0 * velocity_scale);
  s.extrinsic = PoseParameters(RandomPose(rng, extrinsic_angle, extrinsic_translation));
  return s;
}

const std::vector<const ceres::Manifold*>& Manifolds() {
  static const PoseManifold pose;
  static const std::vector<const ceres::Manifold*> m = {&pose,   nullptr, nullptr, &pose,
                                                        nullptr, nullptr, &pose};
  return m;
}

TEST(ContinuousPointToPlaneExtrinsic, ResidualIsContinuousResidualAtRobotFramePoint) {
  std::mt19937 rng(51);
  const auto model = Model(10.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const State s = RandomState(rng, 3.0, 0.5, 2.0, 3.0, 1.0);
    auto interp = std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.1 * u(rng));
    const PlaneAssociation m = RandomAssociation(rng);
    const Vec3 q_l = RandomPoint(rng);
    PlaneAssociation robot = m;
    robot.point_robot = PoseManifold::Pose(s.extrinsic.data()) * q_l;
    const ContinuousPointToPlaneExtrinsic cost(interp, m, q_l);
    const ContinuousPointToPlane reference(interp, robot);
    double r = 0.0, r_reference = 1.0;
    ASSERT_TRUE(cost.Evaluate(s.Params().data(), &r, nullptr));
    ASSERT_TRUE(reference.Evaluate(s.Params().data(), &r_reference, nullptr));
    EXPECT_NEAR(r, r_reference, 1e-12 * (1.0 + std::abs(r_reference)));
    // A different extrinsic moves the point: the residual must change.
    State moved = s;
    moved.extrinsic =
        PoseParameters(SE3::Exp(Vec6::Constant(0.05)) * PoseManifold::Pose(s.extrinsic.data()));
    double r_moved = 0.0;
    ASSERT_TRUE(cost.Evaluate(moved.Params().data(), &r_moved, nullptr));
    EXPECT_GT(std::abs(r_moved - r), 1e-4);
  }
}

void CheckJacobians(double alpha, double max_angle, double max_step, double velocity_scale,
                    double extrinsic_angle, double extrinsic_translation, uint32_t seed) {
  std::mt19937 rng(seed);
  const auto model = Model(alpha);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const State s = RandomState(rng, max_angle, max_step, velocity_scale, extrinsic_angle,
                                extrinsic_translation);
    const double tau = trial == 0 ? 0.0 : (trial == 1 ? 0.1 : 0.1 * u(rng));
    const ContinuousPointToPlaneExtrinsic cost(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, tau), RandomAssociation(rng),
        RandomPoint(rng));
    EXPECT_TRUE(JacobiansMatchNumeric(cost, Manifolds(), s.Params()))
        << "trial " << trial << " tau " << tau;
  }
}

TEST(ContinuousPointToPlaneExtrinsic, JacobiansRandomStates) {
  CheckJacobians(10.0, M_PI, 0.5, 2.0, M_PI, 1.0, 52);
}
TEST(ContinuousPointToPlaneExtrinsic, JacobiansLargeMotion) {
  CheckJacobians(100.0, M_PI, 2.5, 10.0, 1.0, 0.5, 53);
}
// Small angles everywhere: knots and extrinsic within 1e-7 of the identity.
TEST(ContinuousPointToPlaneExtrinsic, JacobiansNearIdentity) {
  CheckJacobians(10.0, 1e-7, 1e-7, 1e-7, 1e-7, 1e-7, 54);
}
// α·Δt → 0 (the Singer model's WNOJ limit, α = 1e-7 /s over 0.1 s) and α = 0 exactly.
TEST(ContinuousPointToPlaneExtrinsic, JacobiansAlphaDtToZero) {
  CheckJacobians(1e-7, M_PI, 0.5, 2.0, 0.5, 0.2, 55);
  CheckJacobians(0.0, M_PI, 0.5, 2.0, 0.5, 0.2, 56);
}

// |φ| near π for the knot k pose and for the extrinsic.
TEST(ContinuousPointToPlaneExtrinsic, JacobiansRotationsNearPi) {
  std::mt19937 rng(57);
  const auto model = Model(10.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    State s = RandomState(rng, 1.0, 0.3, 1.0, 0.5, 0.2);
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    const SE3 T_k(so3::Exp((M_PI - 1e-6) * axis), Vec3(1.0, 2.0, 3.0));
    s.pose_k = PoseParameters(T_k);
    s.pose_k1 = PoseParameters(RandomPose(rng, 0.3, 0.3) * T_k);
    const Vec3 axis_rl = Vec3(u(rng), u(rng), u(rng)).normalized();
    s.extrinsic = PoseParameters(SE3(so3::Exp((M_PI - 1e-6) * axis_rl), Vec3(0.1, -0.2, 0.3)));
    const ContinuousPointToPlaneExtrinsic cost(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.1 * std::abs(u(rng))),
        RandomAssociation(rng), RandomPoint(rng));
    EXPECT_TRUE(JacobiansMatchNumeric(cost, Manifolds(), s.Params())) << trial;
  }
}

// Through a prepared SharedPoseInterpolation (as the window's evaluation callback fills it): the
// same residual and Jacobians as the interpolation computed on demand.
TEST(ContinuousPointToPlaneExtrinsic, PreparedInterpolationGivesSameValues) {
  std::mt19937 rng(58);
  const auto model = Model(10.0);
  const State s = RandomState(rng, 2.0, 0.5, 2.0, 0.3, 0.2);
  const gp::KnotBlocks blocks = {s.pose_k.data(),  s.w_k.data(),  s.dw_k.data(),
                                 s.pose_k1.data(), s.w_k1.data(), s.dw_k1.data()};
  auto interp = std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.037);
  auto shared = std::make_shared<SharedPoseInterpolation>(interp, blocks);
  shared->Prepare();
  ASSERT_TRUE(shared->prepared());
  const PlaneAssociation m = RandomAssociation(rng);
  const Vec3 q_l = RandomPoint(rng);
  const ContinuousPointToPlaneExtrinsic prepared(shared, m, q_l);
  const ContinuousPointToPlaneExtrinsic computed(interp, m, q_l);
  double r_p = 0.0, r_c = 1.0;
  Eigen::Matrix<double, 1, 7> J_p[7], J_c[7];
  double* jp[7];
  double* jc[7];
  for (int b = 0; b < 7; ++b) {
    jp[b] = J_p[b].data();
    jc[b] = J_c[b].data();
  }
  ASSERT_TRUE(prepared.Evaluate(s.Params().data(), &r_p, jp));
  ASSERT_TRUE(computed.Evaluate(s.Params().data(), &r_c, jc));
  EXPECT_NEAR(r_p, r_c, 1e-12);
  for (int b = 0; b < 7; ++b) {
    const int n = (b == 0 || b == 3 || b == 6) ? 7 : 6;
    EXPECT_LT((J_p[b].leftCols(n) - J_c[b].leftCols(n)).norm(), 1e-9) << b;
  }
  EXPECT_TRUE(JacobiansMatchNumeric(prepared, Manifolds(), s.Params()));
}

}  // namespace
}  // namespace ctlio
