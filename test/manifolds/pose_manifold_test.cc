// PoseManifold and RotationManifold: Ceres' manifold invariants at random and
// near-singular points, and the lift used by every cost function on a pose.
#include "ctlio/manifolds/pose_manifold.h"

#include <ceres/ceres.h>
#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/gradient_check.h"

namespace ctlio {
namespace {

using ceres::Vector;
using namespace ceres;  // NOLINT: the manifold invariant matchers live in ceres
constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = 1e-9;

Vector PoseVector(const SE3& T) {
  Vector x(7);
  PoseManifold::Store(T, x.data());
  return x;
}

// q and −q are the same rotation; Plus(x, Minus(y, x)) returns the sign of y
// whose dot product with x's quaternion is positive, so test with that one.
Vector SameHemisphere(Vector y, const Vector& x, int offset) {
  if (y.segment<4>(offset).dot(x.segment<4>(offset)) < 0.0) y.segment<4>(offset) *= -1.0;
  return y;
}

struct Case {
  double angle_x, angle_y, delta_angle;
};

class PoseManifoldInvariants : public ::testing::TestWithParam<Case> {};

TEST_P(PoseManifoldInvariants, Hold) {
  std::mt19937 rng(21);
  std::normal_distribution<double> n;
  const Case c = GetParam();
  const PoseManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 ax = Vec3(n(rng), n(rng), n(rng)).normalized();
    const Vec3 ay = Vec3(n(rng), n(rng), n(rng)).normalized();
    const SE3 X(so3::Exp(c.angle_x * ax), Vec3(n(rng), n(rng), n(rng)) * 3.0);
    const SE3 Y(so3::Exp(c.angle_y * ay), Vec3(n(rng), n(rng), n(rng)) * 3.0);
    const Vector x = PoseVector(X);
    const Vector y = SameHemisphere(PoseVector(Y), x, 3);
    Vector delta(6);
    delta.head<3>() = Vec3(n(rng), n(rng), n(rng));
    delta.tail<3>() = c.delta_angle * Vec3(n(rng), n(rng), n(rng)).normalized();
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

INSTANTIATE_TEST_SUITE_P(RandomAndNearSingular, PoseManifoldInvariants,
                         ::testing::Values(Case{1.0, 2.0, 0.5},           // generic
                                           Case{0.0, 1e-9, 1e-9},         // identity, tiny steps
                                           Case{1e-7, 0.3, 1e-12},        // small angles
                                           Case{kPi - 1e-7, 2.5, 0.2},    // x near π
                                           Case{3.0, kPi - 1e-3, 1.5}));  // large steps

class RotationManifoldInvariants : public ::testing::TestWithParam<Case> {};

TEST_P(RotationManifoldInvariants, Hold) {
  std::mt19937 rng(22);
  std::normal_distribution<double> n;
  const Case c = GetParam();
  const RotationManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    Vector x(4), y(4);
    RotationManifold::Store(so3::Exp(c.angle_x * Vec3(n(rng), n(rng), n(rng)).normalized()),
                            x.data());
    RotationManifold::Store(so3::Exp(c.angle_y * Vec3(n(rng), n(rng), n(rng)).normalized()),
                            y.data());
    y = SameHemisphere(y, x, 0);
    Vector delta = c.delta_angle * Vector(Vec3(n(rng), n(rng), n(rng)).normalized());
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

INSTANTIATE_TEST_SUITE_P(RandomAndNearSingular, RotationManifoldInvariants,
                         ::testing::Values(Case{1.0, 2.0, 0.5}, Case{0.0, 1e-9, 1e-9},
                                           Case{kPi - 1e-7, 2.5, 0.2}, Case{3.0, kPi - 1e-3, 1.5}));

TEST(PoseManifold, PlusIsLeftPerturbationAndMinusIgnoresQuaternionSign) {
  const SE3 T = SE3::Exp((Vec6() << 1, 2, 3, 0.3, -0.4, 1.0).finished());
  const Vec6 d = (Vec6() << 0.1, -0.2, 0.3, 0.05, 0.02, -0.3).finished();
  Vector x = PoseVector(T), out(7);
  PoseManifold().Plus(x.data(), d.data(), out.data());
  const SE3 expected = SE3::Exp(d) * T;
  EXPECT_LT((PoseManifold::Pose(out.data()).Matrix() - expected.Matrix()).norm(), 1e-12);
  Vector flipped = out;
  flipped.tail<4>() *= -1.0;
  Vec6 m1, m2;
  PoseManifold().Minus(out.data(), x.data(), m1.data());
  PoseManifold().Minus(flipped.data(), x.data(), m2.data());
  EXPECT_LT((m1 - d).norm(), 1e-12);
  EXPECT_LT((m2 - d).norm(), 1e-12);
}

// A cost function that lifts its tangent Jacobian passes GradientChecker: the
// convention every ctlio factor on a pose follows.
class PoseLogError final : public ceres::SizedCostFunction<6, 7, 4> {
 public:
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    // r = Log([C, 0]·T): a pose block and a rotation block in one residual.
    const SE3 T = PoseManifold::Pose(p[0]);
    const SE3 R(RotationManifold::Rotation(p[1]), Vec3::Zero());
    const Vec6 r = (R * T).Log();
    Eigen::Map<Vec6>{residuals} = r;
    const Mat6 Jinv = se3::LeftJacobianInverse(r);
    if (jacobians && jacobians[0]) {
      // δT on the left of T becomes Ad(R)δ on the left of R·T.
      LiftPoseJacobian<6>(Jinv * R.Adjoint(), p[0], jacobians[0]);
    }
    if (jacobians && jacobians[1]) {
      Eigen::Matrix<double, 6, 3> d_rot = Jinv.rightCols<3>();
      LiftRotationJacobian<6>(d_rot, p[1], jacobians[1]);
    }
    return true;
  }
};

TEST(PoseManifold, LiftedJacobiansPassGradientChecker) {
  std::mt19937 rng(23);
  const PoseManifold pose_manifold;
  const RotationManifold rotation_manifold;
  const PoseLogError cost;
  for (int i = 0; i < 20; ++i) {
    const auto x = testing::PoseParameters(testing::RandomPose(rng, 2.5, 3.0));
    double q[4];
    RotationManifold::Store(testing::RandomPose(rng, 0.5, 0.0).rotation(), q);
    EXPECT_TRUE(testing::JacobiansMatchNumeric(cost, {&pose_manifold, &rotation_manifold},
                                               {x.data(), q}, 1e-8));
  }
}

}  // namespace
}  // namespace ctlio
