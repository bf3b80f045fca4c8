// PointToPlaneWorldCalibratedBatch (the baseline's calibrated lidar residuals of a scan as one
// block): without a loss its rows are the per-point PointToPlaneWorldCalibrated residuals and its
// Jacobians match central differences (every combination of the optional blocks, fast twists,
// rotations near π, near the identity); with a loss, and in the square-root form, Ceres sees the
// cost, gradient and Gauss–Newton Hessian of the per-point blocks with that loss.
#include "ctlio/factors/lidar/point_to_plane_world_calibrated_batch.h"

#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/gradient_check.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;
using testing::RandomVec6;
using Batch = PointToPlaneWorldCalibratedBatch;
using Form = Batch::Form;

struct Scan {
  std::vector<double> pose, extrinsic, delta;
  double anchor = 0.0;
  std::vector<Batch::Point> points;
};

Scan RandomScan(std::mt19937& rng, int n, double max_angle, double twist_scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Scan s;
  s.pose = PoseParameters(RandomPose(rng, max_angle, 10.0));
  s.extrinsic = PoseParameters(RandomPose(rng, max_angle, 0.5));
  s.anchor = 0.02 * u(rng);
  s.delta = {s.anchor + 0.03 * u(rng)};  // ε up to 30 ms
  for (int i = 0; i < n; ++i) {
    Batch::Point p;
    p.association = RandomAssociation(rng);
    p.point_lidar = 20.0 * Vec3(u(rng), u(rng), u(rng));
    p.deskew = RandomPose(rng, 0.3, 0.3);
    p.twist = RandomVec6(rng, twist_scale);
    s.points.push_back(p);
  }
  return s;
}

std::vector<double*> Blocks(Scan* s, bool extrinsic, bool offset) {
  std::vector<double*> p = {s->pose.data()};
  if (extrinsic) p.push_back(s->extrinsic.data());
  if (offset) p.push_back(s->delta.data());
  return p;
}

std::vector<const ceres::Manifold*> Manifolds(bool extrinsic, bool offset) {
  static const PoseManifold pose;
  std::vector<const ceres::Manifold*> m = {&pose};
  if (extrinsic) m.push_back(&pose);
  if (offset) m.push_back(nullptr);
  return m;
}

std::unique_ptr<PointToPlaneWorldCalibrated> Single(const Scan& s, size_t i, bool extrinsic,
                                                    bool offset) {
  PointToPlaneWorldCalibrated::Geometry g;
  g.deskew = s.points[i].deskew;
  g.twist = s.points[i].twist;
  g.offset_anchor = s.anchor;
  return std::make_unique<PointToPlaneWorldCalibrated>(
      s.points[i].association, s.points[i].point_lidar, g, extrinsic, offset,
      PoseManifold::Pose(s.extrinsic.data()));
}

TEST(PointToPlaneWorldCalibratedBatch, RowsAreThePerPointResidualsWithoutLoss) {
  std::mt19937 rng(71);
  for (const bool extrinsic : {false, true}) {
    for (const bool offset : {false, true}) {
      Scan s = RandomScan(rng, 9, M_PI, 2.0);
      const Batch batch(s.points, s.anchor, nullptr, extrinsic, offset,
                        PoseManifold::Pose(s.extrinsic.data()));
      ASSERT_EQ(batch.num_residuals(), 9);
      const std::vector<double*> blocks = Blocks(&s, extrinsic, offset);
      std::vector<double> r(9, 0.0);
      ASSERT_TRUE(batch.Evaluate(blocks.data(), r.data(), nullptr));
      for (size_t i = 0; i < 9; ++i) {
        double expected = 0.0;
        ASSERT_TRUE(Single(s, i, extrinsic, offset)->Evaluate(blocks.data(), &expected, nullptr));
        EXPECT_EQ(r[i], expected) << i;  // the same code: bit for bit
        EXPECT_GT(std::abs(expected), 1e-6);
      }
    }
  }
}

void CheckJacobians(double max_angle, double twist_scale, uint32_t seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 4; ++trial) {
    for (const bool extrinsic : {false, true}) {
      for (const bool offset : {false, true}) {
        Scan s = RandomScan(rng, 5, max_angle, twist_scale);
        const Batch batch(s.points, s.anchor, nullptr, extrinsic, offset,
                          PoseManifold::Pose(s.extrinsic.data()));
        const std::vector<double*> b = Blocks(&s, extrinsic, offset);
        EXPECT_TRUE(JacobiansMatchNumeric(batch, Manifolds(extrinsic, offset),
                                          std::vector<const double*>(b.begin(), b.end())))
            << "trial " << trial << " extrinsic " << extrinsic << " offset " << offset;
      }
    }
  }
}

TEST(PointToPlaneWorldCalibratedBatch, JacobiansRandomStates) { CheckJacobians(M_PI, 2.0, 72); }
TEST(PointToPlaneWorldCalibratedBatch, JacobiansFastMotion) { CheckJacobians(M_PI, 20.0, 73); }
TEST(PointToPlaneWorldCalibratedBatch, JacobiansNearIdentity) { CheckJacobians(1e-7, 1e-7, 74); }

// |φ| near π for the pose and the extrinsic.
TEST(PointToPlaneWorldCalibratedBatch, JacobiansRotationsNearPi) {
  std::mt19937 rng(75);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    Scan s = RandomScan(rng, 5, 1.0, 2.0);
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    s.pose = PoseParameters(SE3(so3::Exp((M_PI - 1e-6) * axis), Vec3(1.0, 2.0, 3.0)));
    const Vec3 axis_rl = Vec3(u(rng), u(rng), u(rng)).normalized();
    s.extrinsic = PoseParameters(SE3(so3::Exp((M_PI - 1e-6) * axis_rl), Vec3(0.1, -0.2, 0.3)));
    const Batch batch(s.points, s.anchor, nullptr, true, true);
    const std::vector<double*> b = Blocks(&s, true, true);
    EXPECT_TRUE(JacobiansMatchNumeric(batch, Manifolds(true, true),
                                      std::vector<const double*>(b.begin(), b.end())))
        << "trial " << trial;
  }
}

struct Evaluated {
  double cost = 0.0;
  std::vector<double> gradient;
  Eigen::MatrixXd JtJ;
};

// What Ceres sees of `costs` (each with `loss`) at the scan's blocks.
Evaluated EvaluateProblem(const std::vector<ceres::CostFunction*>& costs, ceres::LossFunction* loss,
                          Scan s, bool extrinsic, bool offset) {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  const std::vector<double*> blocks = Blocks(&s, extrinsic, offset);
  for (ceres::CostFunction* cost : costs) problem.AddResidualBlock(cost, loss, blocks);
  PoseManifold pose;
  problem.SetManifold(s.pose.data(), &pose);
  if (extrinsic) problem.SetManifold(s.extrinsic.data(), &pose);
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = blocks;
  Evaluated out;
  ceres::CRSMatrix J;
  EXPECT_TRUE(problem.Evaluate(eval, &out.cost, nullptr, &out.gradient, &J));
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(J.num_rows, J.num_cols);
  for (int row = 0; row < J.num_rows; ++row) {
    for (int k = J.rows[row]; k < J.rows[row + 1]; ++k) dense(row, J.cols[k]) = J.values[k];
  }
  out.JtJ = dense.transpose() * dense;
  return out;
}

// The batch (of `form`, n points) against n one-point blocks with the loss.
void ExpectSameLinearModel(ceres::LossFunction* loss, uint32_t seed, Form form, int n,
                           double tolerance) {
  std::mt19937 rng(seed);
  for (const bool extrinsic : {false, true}) {
    for (const bool offset : {false, true}) {
      const Scan s = RandomScan(rng, n, M_PI, 5.0);
      std::vector<std::unique_ptr<ceres::CostFunction>> owned;
      std::vector<ceres::CostFunction*> singles;
      for (size_t i = 0; i < s.points.size(); ++i) {
        owned.push_back(Single(s, i, extrinsic, offset));
        singles.push_back(owned.back().get());
      }
      Batch batch(
          s.points, s.anchor,
          std::shared_ptr<const ceres::LossFunction>(loss, [](const ceres::LossFunction*) {}),
          extrinsic, offset, PoseManifold::Pose(s.extrinsic.data()), form);
      const int w = 6 + (extrinsic ? 6 : 0) + (offset ? 1 : 0);
      ASSERT_EQ(batch.num_residuals(),
                form == Form::kSquareRoot ? w + 1 : n + (loss != nullptr ? 1 : 0));
      const Evaluated a = EvaluateProblem(singles, loss, s, extrinsic, offset);
      const Evaluated b = EvaluateProblem({&batch}, nullptr, s, extrinsic, offset);
      const std::string where =
          "extrinsic " + std::to_string(extrinsic) + " offset " + std::to_string(offset);
      EXPECT_NEAR(b.cost, a.cost, tolerance * a.cost) << where;
      ASSERT_EQ(a.gradient.size(), b.gradient.size());
      double g_scale = 0.0;
      for (const double v : a.gradient) g_scale = std::max(g_scale, std::abs(v));
      for (size_t i = 0; i < a.gradient.size(); ++i) {
        EXPECT_NEAR(b.gradient[i], a.gradient[i], tolerance * g_scale) << where << " " << i;
      }
      EXPECT_LE((b.JtJ - a.JtJ).cwiseAbs().maxCoeff(), tolerance * a.JtJ.cwiseAbs().maxCoeff())
          << where;
    }
  }
}

// Residuals of a few metres up to ~40 m (weights 0.1–1): scale 2 puts some points inside the
// loss's quadratic part and most far outside it.
TEST(PointToPlaneWorldCalibratedBatch, PointRowsGiveCeresPerPointModelWithLoss) {
  ceres::CauchyLoss cauchy(2.0);
  ceres::HuberLoss huber(2.0);
  ExpectSameLinearModel(&cauchy, 76, Form::kPointRows, 12, 1e-12);
  ExpectSameLinearModel(&huber, 77, Form::kPointRows, 12, 1e-12);
}

TEST(PointToPlaneWorldCalibratedBatch, SquareRootGivesThePerPointModel) {
  ceres::CauchyLoss cauchy(2.0);
  for (const int n : {8, 150}) {
    SCOPED_TRACE("points " + std::to_string(n));
    ExpectSameLinearModel(nullptr, 78, Form::kSquareRoot, n, 1e-10);
    ExpectSameLinearModel(&cauchy, 79, Form::kSquareRoot, n, 1e-10);
  }
}

// A cost-only evaluation of the square-root form: zeros and the whole cost in the last row.
TEST(PointToPlaneWorldCalibratedBatch, SquareRootCostOnlyEvaluationCarriesTheCost) {
  std::mt19937 rng(80);
  Scan s = RandomScan(rng, 40, M_PI, 2.0);
  const auto loss = std::make_shared<const ceres::CauchyLoss>(2.0);
  const Batch rows(s.points, s.anchor, loss, true, true, SE3(), Form::kPointRows);
  const Batch root(s.points, s.anchor, loss, true, true, SE3(), Form::kSquareRoot);
  const std::vector<double*> b = Blocks(&s, true, true);
  std::vector<double> r_rows(41), r_root(14, 1.0);
  ASSERT_TRUE(rows.Evaluate(b.data(), r_rows.data(), nullptr));
  ASSERT_TRUE(root.Evaluate(b.data(), r_root.data(), nullptr));
  double cost_rows = 0.0;
  for (const double r : r_rows) cost_rows += r * r;
  for (int i = 0; i < 13; ++i) EXPECT_EQ(r_root[i], 0.0);
  EXPECT_NEAR(r_root[13] * r_root[13], cost_rows, 1e-12 * cost_rows);
}

TEST(PointToPlaneWorldCalibratedBatch, NoPointsIsAnError) {
  EXPECT_THROW(Batch({}, 0.0, nullptr, true, true), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio
