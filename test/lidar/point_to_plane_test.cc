// The single-pose point-to-plane factors (SPEC §4): PointToPlane on a knot pose T_rm and
// PointToPlaneWorld on a navigation state's T_wb. Residuals against their definition, and
// Jacobians against numeric differentiation at random, large-rotation (|φ| near π) and
// near-identity poses.
#include "ctlio/factors/lidar/point_to_plane.h"

#include <gtest/gtest.h>

#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/lidar/point_to_plane_world.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;

// The residual is w·nᵀ(p_ref − T_rm⁻¹ q), written out independently of the factor.
TEST(PointToPlane, ResidualMatchesDefinition) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const SE3 T_rm = RandomPose(rng, 3.0, 10.0);
    const PlaneAssociation m = RandomAssociation(rng);
    const PointToPlane cost(m);
    const auto x = PoseParameters(T_rm);
    const double* params[] = {x.data()};
    double r = 0.0;
    ASSERT_TRUE(cost.Evaluate(params, &r, nullptr));
    const Mat4 T_mr = T_rm.Matrix().inverse();
    const Vec3 p = (T_mr * m.point_robot.homogeneous()).head<3>();
    EXPECT_NEAR(r, m.weight * m.plane_normal.dot(m.plane_point - p), 1e-9);
  }
}

TEST(PointToPlane, ZeroOnThePlane) {
  std::mt19937 rng(2);
  const SE3 T_rm = RandomPose(rng, 2.0, 5.0);
  PlaneAssociation m = RandomAssociation(rng);
  // Put the plane through the transformed point.
  m.plane_point = T_rm.Inverse() * m.point_robot + 3.0 * m.plane_normal.unitOrthogonal();
  const PointToPlane cost(m);
  const auto x = PoseParameters(T_rm);
  const double* params[] = {x.data()};
  double r = 1.0;
  ASSERT_TRUE(cost.Evaluate(params, &r, nullptr));
  EXPECT_NEAR(r, 0.0, 1e-12);
}

// Factor = PointToPlane (pose block T_rm) or PointToPlaneWorld (pose block T_wb).
template <typename Factor>
void CheckJacobians(double max_angle, uint32_t seed) {
  std::mt19937 rng(seed);
  const PoseManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const SE3 T = RandomPose(rng, max_angle, 10.0);
    const Factor cost(RandomAssociation(rng));
    const auto x = PoseParameters(T);
    EXPECT_TRUE(JacobiansMatchNumeric(cost, {&manifold}, {x.data()}, 1e-8))
        << "trial " << trial << " max_angle " << max_angle;
  }
}

template <typename Factor>
void CheckJacobiansNearPi(uint32_t seed) {
  std::mt19937 rng(seed);
  const PoseManifold manifold;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    const SE3 T(so3::Exp((M_PI - 1e-6 * std::abs(u(rng))) * axis), 5.0 * axis.unitOrthogonal());
    const Factor cost(RandomAssociation(rng));
    const auto x = PoseParameters(T);
    EXPECT_TRUE(JacobiansMatchNumeric(cost, {&manifold}, {x.data()}, 1e-8)) << trial;
  }
}

TEST(PointToPlane, JacobianRandomRotations) { CheckJacobians<PointToPlane>(M_PI, 3); }
TEST(PointToPlane, JacobianLargeRotations) { CheckJacobiansNearPi<PointToPlane>(4); }
TEST(PointToPlane, JacobianSmallRotations) { CheckJacobians<PointToPlane>(1e-7, 5); }

// e = w nᵀ(p_ref − T_wb q): the single-pose residual of the pose T_rm = T_wb⁻¹.
TEST(PointToPlaneWorld, EqualsPointToPlaneOfTheInversePose) {
  std::mt19937 rng(6);
  for (int trial = 0; trial < 20; ++trial) {
    const SE3 T_wb = RandomPose(rng, 3.0, 10.0);
    const PlaneAssociation m = RandomAssociation(rng);
    const auto x_wb = PoseParameters(T_wb), x_rm = PoseParameters(T_wb.Inverse());
    const double* p_wb[] = {x_wb.data()};
    const double* p_rm[] = {x_rm.data()};
    double r_world = 0.0, r = 1.0;
    ASSERT_TRUE(PointToPlaneWorld(m).Evaluate(p_wb, &r_world, nullptr));
    ASSERT_TRUE(PointToPlane(m).Evaluate(p_rm, &r, nullptr));
    EXPECT_NEAR(r_world, m.weight * m.plane_normal.dot(m.plane_point - T_wb * m.point_robot), 1e-9);
    EXPECT_NEAR(r_world, r, 1e-9);
  }
}

TEST(PointToPlaneWorld, JacobianRandomRotations) { CheckJacobians<PointToPlaneWorld>(M_PI, 7); }
TEST(PointToPlaneWorld, JacobianLargeRotations) { CheckJacobiansNearPi<PointToPlaneWorld>(8); }
TEST(PointToPlaneWorld, JacobianSmallRotations) { CheckJacobians<PointToPlaneWorld>(1e-7, 9); }

}  // namespace
}  // namespace ctlio
