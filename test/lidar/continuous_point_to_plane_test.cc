// ContinuousPointToPlane (SPEC §4): its residual is the single-pose residual at the GP-
// interpolated pose, and its Jacobians onto both knots (pose, ϖ, ϖ̇) match numeric
// differentiation at random, large-rotation and near-identity knots, for WNOJ and Singer — also
// through a SharedPoseInterpolation on both of its paths: prepared (as a window's evaluation
// callback fills it before every evaluation) and computed (prepared for other values, as
// ceres::GradientChecker or any direct caller sees it).
#include "ctlio/factors/lidar/continuous_point_to_plane.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "common/singer_model.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;
using testing::RandomVec6;

struct Knots {
  std::vector<double> pose_k, pose_k1;
  Vec6 w_k, dw_k, w_k1, dw_k1;
  std::vector<const double*> Params() const {
    return {pose_k.data(), w_k.data(), dw_k.data(), pose_k1.data(), w_k1.data(), dw_k1.data()};
  }
};

// Knot k random (rotation up to max_angle); knot k+1 = a motion of up to max_step from it.
Knots RandomKnots(std::mt19937& rng, double max_angle, double max_step, double velocity_scale) {
  Knots s;
  const SE3 T_k = RandomPose(rng, max_angle, 10.0);
  const SE3 T_k1 = RandomPose(rng, max_step, max_step) * T_k;
  s.pose_k = PoseParameters(T_k);
  s.pose_k1 = PoseParameters(T_k1);
  s.w_k = RandomVec6(rng, velocity_scale);
  s.dw_k = RandomVec6(rng, 5.0 * velocity_scale);
  s.w_k1 = RandomVec6(rng, velocity_scale);
  s.dw_k1 = RandomVec6(rng, 5.0 * velocity_scale);
  return s;
}

TEST(ContinuousPointToPlane, ResidualIsSinglePoseResidualAtInterpolatedPose) {
  std::mt19937 rng(31);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  for (int trial = 0; trial < 10; ++trial) {
    const Knots s = RandomKnots(rng, 3.0, 0.5, 2.0);
    const double tau = 0.1 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    auto interp = std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, tau);
    const PlaneAssociation m = RandomAssociation(rng);
    const ContinuousPointToPlane cost(interp, m);
    double r = 0.0;
    ASSERT_TRUE(cost.Evaluate(s.Params().data(), &r, nullptr));
    SE3 T_tau;
    interp->Pose(gp::ReadKnotState(s.pose_k.data(), s.w_k.data(), s.dw_k.data()),
                 gp::ReadKnotState(s.pose_k1.data(), s.w_k1.data(), s.dw_k1.data()), &T_tau,
                 nullptr, nullptr);
    const Vec3 p = T_tau.Inverse() * m.point_robot;
    EXPECT_NEAR(r, m.weight * m.plane_normal.dot(m.plane_point - p), 1e-9);
  }
}

// At the knot times the interpolated pose is the knot pose, so the residual equals the
// single-pose factor's.
TEST(ContinuousPointToPlane, AtKnotTimesEqualsSinglePoseFactor) {
  std::mt19937 rng(32);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  const Knots s = RandomKnots(rng, 3.0, 0.5, 2.0);
  const PlaneAssociation m = RandomAssociation(rng);
  for (const auto& [tau, pose] :
       {std::make_pair(0.0, s.pose_k.data()), std::make_pair(0.1, s.pose_k1.data())}) {
    const ContinuousPointToPlane cost(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, tau), m);
    const PointToPlane single(m);
    double r = 0.0, r_single = 1.0;
    ASSERT_TRUE(cost.Evaluate(s.Params().data(), &r, nullptr));
    const double* p[] = {pose};
    ASSERT_TRUE(single.Evaluate(p, &r_single, nullptr));
    EXPECT_NEAR(r, r_single, 1e-9) << tau;
  }
}

void CheckJacobians(bool singer, double max_angle, double max_step, double velocity_scale,
                    uint32_t seed) {
  std::mt19937 rng(seed);
  const auto model = ctlio::testing::NewerCollegeSingerModel(singer);
  const PoseManifold pose_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, nullptr, nullptr,
                                                         &pose_manifold, nullptr, nullptr};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Knots s = RandomKnots(rng, max_angle, max_step, velocity_scale);
    const double tau = trial == 0 ? 0.0 : (trial == 1 ? 0.1 : 0.1 * u(rng));
    const ContinuousPointToPlane cost(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, tau), RandomAssociation(rng));
    EXPECT_TRUE(JacobiansMatchNumeric(cost, manifolds, s.Params()))
        << "trial " << trial << " tau " << tau;
  }
}

TEST(ContinuousPointToPlane, JacobiansRandomKnotsSinger) {
  CheckJacobians(true, M_PI, 0.5, 2.0, 33);
}
TEST(ContinuousPointToPlane, JacobiansRandomKnotsWnoj) {
  CheckJacobians(false, M_PI, 0.5, 2.0, 34);
}
TEST(ContinuousPointToPlane, JacobiansLargeMotion) { CheckJacobians(true, M_PI, 2.5, 10.0, 35); }
TEST(ContinuousPointToPlane, JacobiansNearIdentity) { CheckJacobians(true, 1e-7, 1e-7, 1e-7, 36); }

TEST(ContinuousPointToPlane, JacobiansKnotNearPi) {
  std::mt19937 rng(37);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  const PoseManifold pose_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, nullptr, nullptr,
                                                         &pose_manifold, nullptr, nullptr};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    Knots s = RandomKnots(rng, 1.0, 0.3, 1.0);
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    const SE3 T_k(so3::Exp((M_PI - 1e-6) * axis), Vec3(1.0, 2.0, 3.0));
    s.pose_k = PoseParameters(T_k);
    s.pose_k1 = PoseParameters(RandomPose(rng, 0.3, 0.3) * T_k);
    const ContinuousPointToPlane cost(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.1 * std::abs(u(rng))),
        RandomAssociation(rng));
    EXPECT_TRUE(JacobiansMatchNumeric(cost, manifolds, s.Params())) << trial;
  }
}

// Ceres may ask for any subset of the Jacobians: each must equal the full evaluation's.
TEST(ContinuousPointToPlane, PartialJacobianRequests) {
  std::mt19937 rng(38);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  const Knots s = RandomKnots(rng, 2.0, 0.5, 2.0);
  const ContinuousPointToPlane cost(
      std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.037), RandomAssociation(rng));
  double full[6][7], part[6][7];
  double* full_ptrs[6];
  for (int i = 0; i < 6; ++i) full_ptrs[i] = full[i];
  double r_full, r_part;
  ASSERT_TRUE(cost.Evaluate(s.Params().data(), &r_full, full_ptrs));
  for (int only = 0; only < 6; ++only) {
    double* ptrs[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
    ptrs[only] = part[only];
    ASSERT_TRUE(cost.Evaluate(s.Params().data(), &r_part, ptrs));
    EXPECT_EQ(r_part, r_full);
    const int n = (only % 3 == 0) ? 7 : 6;
    for (int j = 0; j < n; ++j) EXPECT_EQ(part[only][j], full[only][j]) << only << " " << j;
  }
}

// ---- The shared interpolation of one firing, exactly as a window evaluates it ----------------

// Knot blocks a SharedPoseInterpolation is bound to (the window's storage).
struct BoundKnots {
  Knots values;
  SharedPoseInterpolation::KnotBlocks Blocks() const {
    return {values.pose_k.data(),  values.w_k.data(),  values.dw_k.data(),
            values.pose_k1.data(), values.w_k1.data(), values.dw_k1.data()};
  }
  void Set(double const* const* p) {
    std::copy(p[0], p[0] + 7, values.pose_k.begin());
    values.w_k = Eigen::Map<const Vec6>(p[1]);
    values.dw_k = Eigen::Map<const Vec6>(p[2]);
    std::copy(p[3], p[3] + 7, values.pose_k1.begin());
    values.w_k1 = Eigen::Map<const Vec6>(p[4]);
    values.dw_k1 = Eigen::Map<const Vec6>(p[5]);
  }
};

// The factor as Ceres evaluates it inside a window: before every evaluation the point is copied
// into the parameter blocks and the evaluation callback prepares the firing
// (ceres::EvaluationCallback's contract), so every value and Jacobian, the numeric ones
// included, comes through the prepared interpolation.
class PreparedEvaluation final : public ceres::SizedCostFunction<1, 7, 6, 6, 7, 6, 6> {
 public:
  PreparedEvaluation(const ContinuousPointToPlane* cost, SharedPoseInterpolation* shared,
                     BoundKnots* blocks)
      : cost_(cost), shared_(shared), blocks_(blocks) {}
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    blocks_->Set(p);
    shared_->Prepare();
    return cost_->Evaluate(p, r, J);
  }

 private:
  const ContinuousPointToPlane* cost_;
  SharedPoseInterpolation* shared_;
  BoundKnots* blocks_;
};

// Random, large-rotation (|φ| of knot k near π, big motion) and near-singular (tiny angles and
// twists) knots.
Knots KnotsOfKind(std::mt19937& rng, int kind) {
  if (kind == 0) return RandomKnots(rng, M_PI, 0.5, 2.0);
  if (kind == 2) return RandomKnots(rng, 1e-7, 1e-7, 1e-7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Knots s = RandomKnots(rng, 1.0, 2.5, 10.0);
  const SE3 T_k(so3::Exp((M_PI - 1e-6) * Vec3(u(rng), u(rng), u(rng)).normalized()),
                Vec3(1.0, 2.0, 3.0));
  s.pose_k = PoseParameters(T_k);
  s.pose_k1 = PoseParameters(RandomPose(rng, 2.5, 2.5) * T_k);
  return s;
}

void CheckSharedJacobians(bool prepared, uint32_t seed) {
  std::mt19937 rng(seed);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  const PoseManifold pose_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, nullptr, nullptr,
                                                         &pose_manifold, nullptr, nullptr};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 9; ++trial) {
    const int kind = trial % 3;
    BoundKnots blocks{KnotsOfKind(rng, kind)};
    const Knots at = blocks.values;  // the point checked
    auto shared = std::make_shared<SharedPoseInterpolation>(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.1 * u(rng)), blocks.Blocks());
    const ContinuousPointToPlane cost(shared, RandomAssociation(rng));
    if (prepared) {
      const PreparedEvaluation as_in_window(&cost, shared.get(), &blocks);
      EXPECT_TRUE(JacobiansMatchNumeric(as_in_window, manifolds, at.Params()))
          << "kind " << kind << " trial " << trial;
      EXPECT_EQ(shared->num_computed(), 0) << "every evaluation must read the prepared values";
    } else {
      // Prepared for other values (the last point Ceres evaluated, say): the factor must notice
      // and interpolate at the parameters it is given.
      const Knots other = KnotsOfKind(rng, kind);
      blocks.Set(other.Params().data());
      shared->Prepare();
      EXPECT_TRUE(JacobiansMatchNumeric(cost, manifolds, at.Params()))
          << "kind " << kind << " trial " << trial;
      EXPECT_GT(shared->num_computed(), 0);
    }
  }
}

TEST(ContinuousPointToPlane, SharedJacobiansPreparedPath) { CheckSharedJacobians(true, 39); }
TEST(ContinuousPointToPlane, SharedJacobiansComputedPath) { CheckSharedJacobians(false, 40); }

// Prepared and computed give the same residual and Jacobians, bit for bit, and equal the factor
// built on a plain interpolator.
TEST(ContinuousPointToPlane, PreparedEqualsComputed) {
  std::mt19937 rng(41);
  const auto model = ctlio::testing::NewerCollegeSingerModel(true);
  const BoundKnots blocks{RandomKnots(rng, 2.0, 0.5, 2.0)};
  const auto interpolator = std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.061);
  const PlaneAssociation m = RandomAssociation(rng);
  auto shared = std::make_shared<SharedPoseInterpolation>(interpolator, blocks.Blocks());
  const ContinuousPointToPlane with_shared(shared, m), plain(interpolator, m);
  double J[2][6][7], r[2];
  double* ptrs[2][6];
  for (int c = 0; c < 2; ++c) {
    for (int b = 0; b < 6; ++b) ptrs[c][b] = J[c][b];
  }
  shared->Prepare();
  ASSERT_TRUE(with_shared.Evaluate(blocks.values.Params().data(), &r[0], ptrs[0]));
  EXPECT_EQ(shared->num_computed(), 0);
  ASSERT_TRUE(plain.Evaluate(blocks.values.Params().data(), &r[1], ptrs[1]));
  EXPECT_EQ(r[0], r[1]);
  for (int b = 0; b < 6; ++b) {
    for (int j = 0; j < (b % 3 == 0 ? 7 : 6); ++j) EXPECT_EQ(J[0][b][j], J[1][b][j]) << b << j;
  }
}

}  // namespace
}  // namespace ctlio
