// MarginalizationPrior: residual definition and analytic Jacobians (GradientChecker) on pose,
// rotation and Euclidean blocks far from the linearisation point, including large rotations.
#include "ctlio/factors/priors/marginalization_prior.h"

#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomPose;
using testing::RandomVec6;

std::vector<double> RotationParameters(const Mat3& C) {
  std::vector<double> q(4);
  RotationManifold::Store(C, q.data());
  return q;
}

Eigen::MatrixXd RandomMatrix(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd A(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) A(i, j) = n(rng);
  return A;
}

// Blocks: pose, rotation, Euclidean 6, pose, Euclidean 2 (tangent 6+3+6+6+2 = 23).
struct Fixture {
  PoseManifold pose;
  RotationManifold rotation;
  std::vector<const ceres::Manifold*> manifolds;
  std::vector<int> sizes = {7, 4, 6, 7, 2};
  std::vector<std::vector<double>> x_bar, x;
  Eigen::MatrixXd A;
  Eigen::VectorXd r0;
  Eigen::VectorXd delta;  // x = x̄ ⊞ δ, stacked tangent
  std::unique_ptr<MarginalizationPrior> prior;

  Fixture(std::mt19937& rng, double max_angle, double delta_angle, int rank) {
    manifolds = {&pose, &rotation, nullptr, &pose, nullptr};
    x_bar = {PoseParameters(RandomPose(rng, max_angle, 5.0)),
             RotationParameters(RandomPose(rng, max_angle, 0.0).rotation()),
             {},
             PoseParameters(RandomPose(rng, max_angle, 5.0)),
             {0.3, -1.2}};
    const Vec6 v = RandomVec6(rng, 3.0);
    x_bar[2].assign(v.data(), v.data() + 6);
    delta.resize(23);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 23; ++i) delta[i] = 2.0 * u(rng);
    // Rotation parts with the requested angle (< π so that Minus(Plus(x̄, δ), x̄) = δ).
    for (int offset : {3, 6, 18}) {
      const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
      delta.segment<3>(offset) = delta_angle * axis;
    }
    const int offsets[] = {0, 6, 9, 15, 21};
    x.resize(5);
    for (int i = 0; i < 5; ++i) {
      x[i].resize(sizes[i]);
      if (manifolds[i] == nullptr) {
        for (int j = 0; j < sizes[i]; ++j) x[i][j] = x_bar[i][j] + delta[offsets[i] + j];
      } else {
        manifolds[i]->Plus(x_bar[i].data(), delta.data() + offsets[i], x[i].data());
      }
    }
    A = RandomMatrix(rng, rank, 23);
    r0 = RandomMatrix(rng, rank, 1);
    std::vector<const double*> points;
    for (const auto& p : x_bar) points.push_back(p.data());
    prior = std::make_unique<MarginalizationPrior>(manifolds, sizes, points, A, r0);
  }

  std::vector<const double*> Parameters() const {
    std::vector<const double*> p;
    for (const auto& b : x) p.push_back(b.data());
    return p;
  }
};

// r(x̄ ⊞ δ) = A·δ + r0 exactly (Minus(Plus(x̄, δ), x̄) = δ for rotation angles < π).
TEST(MarginalizationPrior, ResidualIsLinearInTangentOffset) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 10; ++trial) {
    Fixture f(rng, 3.0, 2.5, 15);
    Eigen::VectorXd r(15);
    ASSERT_TRUE(f.prior->Evaluate(f.Parameters().data(), r.data(), nullptr));
    EXPECT_LT((r - (f.A * f.delta + f.r0)).norm(), 1e-10 * (1.0 + r.norm()));
    std::vector<const double*> at_bar;
    for (const auto& p : f.x_bar) at_bar.push_back(p.data());
    ASSERT_TRUE(f.prior->Evaluate(at_bar.data(), r.data(), nullptr));
    EXPECT_LT((r - f.r0).norm(), 1e-12);
  }
}

struct JacobianCase {
  const char* name;
  double max_angle;    // rotation of x̄
  double delta_angle;  // rotation between x and x̄
  double precision;    // GradientChecker relative precision
};

class MarginalizationPriorJacobian : public ::testing::TestWithParam<JacobianCase> {};

TEST_P(MarginalizationPriorJacobian, MatchesNumeric) {
  std::mt19937 rng(2);
  const JacobianCase c = GetParam();
  for (int trial = 0; trial < 10; ++trial) {
    Fixture f(rng, c.max_angle, c.delta_angle, 11);
    EXPECT_TRUE(JacobiansMatchNumeric(*f.prior, f.manifolds, f.Parameters(), c.precision))
        << c.name << " trial " << trial;
  }
}

INSTANTIATE_TEST_SUITE_P(
    States, MarginalizationPriorJacobian,
    // Within ~0.04 rad of π, J⁻¹ varies fast (cot(θ/2) terms) and the numeric derivative's
    // steps come close to Log's branch cut, so the central differences themselves are only good
    // to ~1e-6 there; everywhere else the check is at 1e-7.
    ::testing::Values(JacobianCase{"translation_offset_only", 1.0, 0.0, 1e-7},
                      JacobianCase{"small_offset", 1.0, 1e-6, 1e-7},
                      JacobianCase{"moderate_offset", 2.0, 0.7, 1e-7},
                      JacobianCase{"large_rotation_offset", 3.1, 2.8, 1e-7},
                      JacobianCase{"near_pi_offset", 3.1, 3.1, 1e-5}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(MarginalizationPrior, RejectsUnsupportedManifoldsAndBadSizes) {
  const double x[7] = {0, 0, 0, 0, 0, 0, 1};
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(6, 6);
  const Eigen::VectorXd r0 = Eigen::VectorXd::Zero(6);
  PoseManifold pose;
  ceres::EuclideanManifold<6> euclidean;
  ceres::EigenQuaternionManifold quaternion;
  EXPECT_NO_THROW(MarginalizationPrior({&pose}, {7}, {x}, A, r0));
  EXPECT_THROW(MarginalizationPrior({&euclidean}, {6}, {x}, A, r0), std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({&quaternion}, {4}, {x}, A.topLeftCorner(3, 3), r0.head(3)),
               std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({&pose}, {6}, {x}, A, r0), std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({nullptr}, {5}, {x}, A, r0), std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({&pose}, {7}, {x}, A, r0.head(5)), std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({&pose}, {7}, {x}, Eigen::MatrixXd(0, 6), r0.head(0)),
               std::invalid_argument);
  EXPECT_THROW(MarginalizationPrior({}, {}, {}, A, r0), std::invalid_argument);
  Eigen::MatrixXd bad = A;
  bad(2, 3) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(MarginalizationPrior({&pose}, {7}, {x}, bad, r0), std::invalid_argument);
  try {
    MarginalizationPrior({&euclidean}, {6}, {x}, A, r0);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("marginalization_prior.cc"), std::string::npos);
  }
}

}  // namespace
}  // namespace ctlio
