// PointToPlaneWorldCalibrated (the baseline's lidar residual with the extrinsic and the clock
// offset as states): at ε = 0 it is PointToPlaneWorld's at the point D·T_rl·q_l; a clock offset
// away from the anchor moves the point along the twist; and its Jacobians onto T_wb, T_rl and δ
// match central differences at random non-trivial states (every combination of the optional
// blocks, rotations near π, near the identity).
#include "ctlio/factors/lidar/point_to_plane_world_calibrated.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/lidar/point_to_plane_world.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;
using testing::RandomVec6;

struct State {
  std::vector<double> pose, extrinsic, delta;
  PointToPlaneWorldCalibrated::Geometry geometry;
  Vec3 q_l;
};

State RandomState(std::mt19937& rng, double max_angle, double twist_scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.pose = PoseParameters(RandomPose(rng, max_angle, 10.0));
  s.extrinsic = PoseParameters(RandomPose(rng, max_angle, 0.5));
  s.geometry.deskew = RandomPose(rng, 0.3, 0.3);
  s.geometry.twist = RandomVec6(rng, twist_scale);
  s.geometry.offset_anchor = 0.02 * u(rng);
  s.delta = {s.geometry.offset_anchor + 0.03 * u(rng)};  // ε up to 30 ms
  s.q_l = 20.0 * Vec3(u(rng), u(rng), u(rng));
  return s;
}

std::vector<const double*> Params(const State& s, bool extrinsic, bool offset) {
  std::vector<const double*> p = {s.pose.data()};
  if (extrinsic) p.push_back(s.extrinsic.data());
  if (offset) p.push_back(s.delta.data());
  return p;
}

std::vector<const ceres::Manifold*> Manifolds(bool extrinsic, bool offset) {
  static const PoseManifold pose;
  std::vector<const ceres::Manifold*> m = {&pose};
  if (extrinsic) m.push_back(&pose);
  if (offset) m.push_back(nullptr);
  return m;
}

TEST(PointToPlaneWorldCalibrated, AtTheAnchorItIsThePointToPlaneResidual) {
  std::mt19937 rng(61);
  for (int trial = 0; trial < 10; ++trial) {
    State s = RandomState(rng, 3.0, 2.0);
    s.delta[0] = s.geometry.offset_anchor;
    const PlaneAssociation m = RandomAssociation(rng);
    PlaneAssociation robot = m;
    robot.point_robot = s.geometry.deskew * (PoseManifold::Pose(s.extrinsic.data()) * s.q_l);
    const PointToPlaneWorld reference(robot);
    double r_reference = 0.0;
    const double* pose = s.pose.data();
    ASSERT_TRUE(reference.Evaluate(&pose, &r_reference, nullptr));
    for (const bool extrinsic : {false, true}) {
      for (const bool offset : {false, true}) {
        const PointToPlaneWorldCalibrated cost(m, s.q_l, s.geometry, extrinsic, offset,
                                               PoseManifold::Pose(s.extrinsic.data()));
        double r = 1.0;
        ASSERT_TRUE(cost.Evaluate(Params(s, extrinsic, offset).data(), &r, nullptr));
        EXPECT_NEAR(r, r_reference, 1e-12 * (1.0 + std::abs(r_reference)));
      }
    }
    // δ 10 ms before the anchor: the point carried by Exp(ε·ξ), ε = 10 ms, along the twist.
    const PointToPlaneWorldCalibrated cost(m, s.q_l, s.geometry, false, true,
                                           PoseManifold::Pose(s.extrinsic.data()));
    const std::vector<double> later = {s.geometry.offset_anchor - 0.01};
    const double* p[2] = {s.pose.data(), later.data()};
    double r_later = 0.0;
    ASSERT_TRUE(cost.Evaluate(p, &r_later, nullptr));
    PlaneAssociation carried = robot;
    carried.point_robot = SE3::Exp(0.01 * s.geometry.twist) * robot.point_robot;
    double r_carried = 1.0;
    ASSERT_TRUE(PointToPlaneWorld(carried).Evaluate(&pose, &r_carried, nullptr));
    EXPECT_NEAR(r_later, r_carried, 1e-12 * (1.0 + std::abs(r_carried))) << trial;
    EXPECT_GT(std::abs(r_later - r_reference), 1e-6);
  }
}

void CheckJacobians(double max_angle, double twist_scale, uint32_t seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 10; ++trial) {
    const State s = RandomState(rng, max_angle, twist_scale);
    const PlaneAssociation m = RandomAssociation(rng);
    for (const bool extrinsic : {false, true}) {
      for (const bool offset : {false, true}) {
        const PointToPlaneWorldCalibrated cost(m, s.q_l, s.geometry, extrinsic, offset,
                                               PoseManifold::Pose(s.extrinsic.data()));
        EXPECT_TRUE(
            JacobiansMatchNumeric(cost, Manifolds(extrinsic, offset), Params(s, extrinsic, offset)))
            << "trial " << trial << " extrinsic " << extrinsic << " offset " << offset;
      }
    }
  }
}

TEST(PointToPlaneWorldCalibrated, JacobiansRandomStates) { CheckJacobians(M_PI, 2.0, 62); }
TEST(PointToPlaneWorldCalibrated, JacobiansFastMotion) { CheckJacobians(M_PI, 20.0, 63); }
TEST(PointToPlaneWorldCalibrated, JacobiansNearIdentity) { CheckJacobians(1e-7, 1e-7, 64); }

// |φ| near π for the pose and the extrinsic.
TEST(PointToPlaneWorldCalibrated, JacobiansRotationsNearPi) {
  std::mt19937 rng(65);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    State s = RandomState(rng, 1.0, 2.0);
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    s.pose = PoseParameters(SE3(so3::Exp((M_PI - 1e-6) * axis), Vec3(1.0, 2.0, 3.0)));
    const Vec3 axis_rl = Vec3(u(rng), u(rng), u(rng)).normalized();
    s.extrinsic = PoseParameters(SE3(so3::Exp((M_PI - 1e-6) * axis_rl), Vec3(0.1, -0.2, 0.3)));
    const PointToPlaneWorldCalibrated cost(RandomAssociation(rng), s.q_l, s.geometry, true, true);
    EXPECT_TRUE(JacobiansMatchNumeric(cost, Manifolds(true, true), Params(s, true, true)))
        << "trial " << trial;
  }
}

}  // namespace
}  // namespace ctlio
