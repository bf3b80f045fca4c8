// ContinuousPointToPlaneBatch (SPEC §4): without a loss, row i is keypoint i's
// ContinuousPointToPlane (with the extrinsic: ContinuousPointToPlaneExtrinsic) residual and the
// Jacobians match numeric differentiation (random, large-rotation / |φ| near π and near-identity
// knots and extrinsics, points sharing a firing); with a Cauchy or Huber loss, Ceres sees the
// cost, gradient and Gauss–Newton Hessian of N one-point blocks with that loss
// (ceres::Problem::Evaluate of both problems); a convex loss fails the evaluation instead of
// returning a wrong cost. The square-root form (W + 1 rows) gives Ceres the same cost, gradient and
// Gauss–Newton Hessian as the point rows, with and without a loss and the extrinsic, over several
// row chunks, for a rank-deficient batch (one firing) too, and the same values for any row runner.
#include "ctlio/factors/lidar/continuous_point_to_plane_batch.h"

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "common/singer_model.h"
#include "ctlio/factors/lidar/continuous_point_to_plane_extrinsic.h"
#include "lidar/random_association.h"

namespace ctlio {
namespace {

using testing::JacobiansMatchNumeric;
using testing::PoseParameters;
using testing::RandomAssociation;
using testing::RandomPose;
using testing::RandomVec6;

// The knot blocks and, for the extrinsic form, T_rl.
struct Knots {
  std::vector<double> pose_k, pose_k1, extrinsic;
  Vec6 w_k, dw_k, w_k1, dw_k1;
  std::vector<const double*> Params() const {
    std::vector<const double*> p = {pose_k.data(),  w_k.data(),  dw_k.data(),
                                    pose_k1.data(), w_k1.data(), dw_k1.data()};
    if (!extrinsic.empty()) p.push_back(extrinsic.data());
    return p;
  }
};

// kind 0: random; 1: knot k rotated by nearly π, a large motion to k+1; 2: near identity.
Knots KnotsOfKind(std::mt19937& rng, int kind) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double angle = kind == 2 ? 1e-7 : M_PI, step = kind == 0 ? 0.5 : (kind == 1 ? 2.5 : 1e-7);
  const double velocity = kind == 0 ? 2.0 : (kind == 1 ? 10.0 : 1e-7);
  SE3 T_k = RandomPose(rng, angle, 10.0);
  if (kind == 1) {
    T_k = SE3(so3::Exp((M_PI - 1e-6) * Vec3(u(rng), u(rng), u(rng)).normalized()),
              Vec3(1.0, 2.0, 3.0));
  }
  Knots s;
  s.pose_k = PoseParameters(T_k);
  s.pose_k1 = PoseParameters(RandomPose(rng, step, step) * T_k);
  s.w_k = RandomVec6(rng, velocity);
  s.dw_k = RandomVec6(rng, 5.0 * velocity);
  s.w_k1 = RandomVec6(rng, velocity);
  s.dw_k1 = RandomVec6(rng, 5.0 * velocity);
  s.extrinsic = PoseParameters(RandomPose(rng, kind == 2 ? 1e-7 : M_PI, 0.5));
  return s;
}

Knots WithoutExtrinsic(Knots s) {
  s.extrinsic.clear();
  return s;
}

// n points on [0, 0.1] s, the last two on one firing (one shared interpolation).
std::vector<ContinuousPointToPlaneBatch::Point> RandomPoints(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto model = ctlio::testing::NewerCollegeSingerModel();
  std::vector<ContinuousPointToPlaneBatch::Point> points;
  std::shared_ptr<const SharedPoseInterpolation> firing;
  for (int i = 0; i < n; ++i) {
    if (i < n - 1) {
      const double tau = i == 0 ? 0.0 : (i == 1 ? 0.1 : 0.1 * u(rng));
      firing = std::make_shared<const SharedPoseInterpolation>(
          std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, tau));
    }
    const PlaneAssociation m = RandomAssociation(rng);
    points.push_back({firing, m, 0.5 * m.point_robot + Vec3(0.3, -0.2, 0.1)});
  }
  return points;
}

TEST(ContinuousPointToPlaneBatch, RowsAreThePerPointResidualsWithoutLoss) {
  std::mt19937 rng(51);
  const auto points = RandomPoints(rng, 6);
  const ContinuousPointToPlaneBatch batch(points, nullptr);
  ASSERT_EQ(batch.num_residuals(), 6);
  const Knots s = KnotsOfKind(rng, 0);
  std::vector<double> r(6);
  ASSERT_TRUE(batch.Evaluate(WithoutExtrinsic(s).Params().data(), r.data(), nullptr));
  const ContinuousPointToPlaneBatch with_extrinsic(points, nullptr, /*with_extrinsic=*/true);
  ASSERT_EQ(with_extrinsic.parameter_block_sizes().size(), 7u);
  std::vector<double> r_rl(6);
  ASSERT_TRUE(with_extrinsic.Evaluate(s.Params().data(), r_rl.data(), nullptr));
  for (size_t i = 0; i < points.size(); ++i) {
    const ContinuousPointToPlane single(points[i].pose, points[i].association);
    double e = 0.0;
    ASSERT_TRUE(single.Evaluate(s.Params().data(), &e, nullptr));
    EXPECT_EQ(r[i], e) << i;
    const ContinuousPointToPlaneExtrinsic single_rl(points[i].pose, points[i].association,
                                                    points[i].point_lidar);
    ASSERT_TRUE(single_rl.Evaluate(s.Params().data(), &e, nullptr));
    EXPECT_EQ(r_rl[i], e) << i;
  }
}

TEST(ContinuousPointToPlaneBatch, JacobiansWithoutLossMatchNumeric) {
  std::mt19937 rng(52);
  const PoseManifold pose;
  const std::vector<const ceres::Manifold*> manifolds = {&pose, nullptr, nullptr,
                                                         &pose, nullptr, nullptr};
  const std::vector<const ceres::Manifold*> manifolds_rl = {&pose,   nullptr, nullptr, &pose,
                                                            nullptr, nullptr, &pose};
  for (int trial = 0; trial < 9; ++trial) {
    const int kind = trial % 3;
    const auto points = RandomPoints(rng, 5);
    const Knots at = KnotsOfKind(rng, kind);
    const ContinuousPointToPlaneBatch batch(points, nullptr);
    EXPECT_TRUE(JacobiansMatchNumeric(batch, manifolds, WithoutExtrinsic(at).Params()))
        << "kind " << kind << " trial " << trial;
    const ContinuousPointToPlaneBatch with_extrinsic(points, nullptr, /*with_extrinsic=*/true);
    EXPECT_TRUE(JacobiansMatchNumeric(with_extrinsic, manifolds_rl, at.Params()))
        << "with the extrinsic, kind " << kind << " trial " << trial;
  }
}

// The two problems Ceres would solve: N one-point blocks with the loss, and the batch.
struct Evaluated {
  double cost = 0.0;
  std::vector<double> gradient;
  Eigen::MatrixXd JtJ;
};

Evaluated EvaluateProblem(const std::vector<ceres::CostFunction*>& costs, ceres::LossFunction* loss,
                          const Knots& at) {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  Knots x = at;  // the problem's own blocks
  std::vector<double*> blocks = {x.pose_k.data(),  x.w_k.data(),  x.dw_k.data(),
                                 x.pose_k1.data(), x.w_k1.data(), x.dw_k1.data()};
  if (!x.extrinsic.empty()) blocks.push_back(x.extrinsic.data());
  for (ceres::CostFunction* cost : costs) problem.AddResidualBlock(cost, loss, blocks);
  PoseManifold pose;
  problem.SetManifold(x.pose_k.data(), &pose);
  problem.SetManifold(x.pose_k1.data(), &pose);
  if (!x.extrinsic.empty()) problem.SetManifold(x.extrinsic.data(), &pose);
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

using Form = ContinuousPointToPlaneBatch::Form;

// The batch (of `form`, `n` points) against n one-point blocks with the loss: cost, gradient and
// JᵀJ within `tolerance` of their largest entries (the cost of itself).
void ExpectSameLinearModel(ceres::LossFunction* loss, uint32_t seed, Form form = Form::kPointRows,
                           int n = 12, double tolerance = 1e-12) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 6; ++trial) {
    const int kind = trial % 3;
    const bool extrinsic = trial >= 3;
    const auto points = RandomPoints(rng, n);
    const Knots at = extrinsic ? KnotsOfKind(rng, kind) : WithoutExtrinsic(KnotsOfKind(rng, kind));
    std::vector<std::unique_ptr<ceres::CostFunction>> owned;
    std::vector<ceres::CostFunction*> singles;
    for (const auto& p : points) {
      if (extrinsic) {
        owned.push_back(std::make_unique<ContinuousPointToPlaneExtrinsic>(p.pose, p.association,
                                                                          p.point_lidar));
      } else {
        owned.push_back(std::make_unique<ContinuousPointToPlane>(p.pose, p.association));
      }
      singles.push_back(owned.back().get());
    }
    // The batch shares the loss without owning it (the problem above does not own it either).
    ContinuousPointToPlaneBatch batch(
        points, std::shared_ptr<const ceres::LossFunction>(loss, [](const ceres::LossFunction*) {}),
        extrinsic, form);
    // Point rows: one per point and the constant row (with a loss); square root: W + 1.
    const int rows =
        form == Form::kSquareRoot ? (extrinsic ? 43 : 37) : n + (loss != nullptr ? 1 : 0);
    ASSERT_EQ(batch.num_residuals(), rows);
    const Evaluated a = EvaluateProblem(singles, loss, at);
    const Evaluated b = EvaluateProblem({&batch}, nullptr, at);
    EXPECT_NEAR(b.cost, a.cost, tolerance * a.cost) << "trial " << trial;
    ASSERT_EQ(a.gradient.size(), b.gradient.size());
    const double g_scale = Eigen::Map<const Eigen::VectorXd>(
                               a.gradient.data(), static_cast<Eigen::Index>(a.gradient.size()))
                               .cwiseAbs()
                               .maxCoeff();
    for (size_t i = 0; i < a.gradient.size(); ++i) {
      EXPECT_NEAR(b.gradient[i], a.gradient[i], tolerance * g_scale)
          << "trial " << trial << " " << i;
    }
    EXPECT_LE((b.JtJ - a.JtJ).cwiseAbs().maxCoeff(), tolerance * a.JtJ.cwiseAbs().maxCoeff())
        << "trial " << trial;
  }
}

// The random planes give residuals of a few metres up to ~40 m (weights 0.1–1): scale 2 puts
// some points inside the loss's quadratic part and most far outside it.
TEST(ContinuousPointToPlaneBatch, CauchyGivesCeresPerPointCostGradientAndHessian) {
  ceres::CauchyLoss loss(2.0);
  ExpectSameLinearModel(&loss, 53);
}

TEST(ContinuousPointToPlaneBatch, HuberGivesCeresPerPointCostGradientAndHessian) {
  ceres::HuberLoss loss(2.0);
  ExpectSameLinearModel(&loss, 54);
}

// The square-root form: 12 points (one chunk, fewer points than rows: allowed, if pointless) and
// 150 (three chunks of 64, 64 and 22 rows). Measured differences: <= 3e-13 of the largest entry
// (the LDLᵀ and its triangular solves add rounding the point rows do not have).
TEST(ContinuousPointToPlaneBatch, SquareRootGivesThePointRowsCostGradientAndHessian) {
  ceres::CauchyLoss cauchy(2.0);
  ceres::HuberLoss huber(2.0);
  for (const int n : {12, 150}) {
    SCOPED_TRACE("points " + std::to_string(n));
    ExpectSameLinearModel(nullptr, 60, Form::kSquareRoot, n, 1e-10);
    ExpectSameLinearModel(&cauchy, 61, Form::kSquareRoot, n, 1e-10);
    ExpectSameLinearModel(&huber, 62, Form::kSquareRoot, n, 1e-10);
  }
}

// Without Jacobians (a cost-only evaluation: Ceres' trial points) the square-root form returns
// zeros and the whole cost in its last row: ½‖r‖² is the point rows' cost. With Jacobians the
// rows differ, their squares summing to the same cost.
TEST(ContinuousPointToPlaneBatch, SquareRootCostOnlyEvaluationCarriesTheCost) {
  std::mt19937 rng(63);
  const auto loss = std::make_shared<const ceres::CauchyLoss>(2.0);
  const auto points = RandomPoints(rng, 100);
  const ContinuousPointToPlaneBatch rows(points, loss);
  const ContinuousPointToPlaneBatch root(points, loss, false, Form::kSquareRoot);
  const Knots s = WithoutExtrinsic(KnotsOfKind(rng, 1));
  std::vector<double> r(rows.num_residuals()), q(root.num_residuals(), -1.0);
  ASSERT_TRUE(rows.Evaluate(s.Params().data(), r.data(), nullptr));
  ASSERT_TRUE(root.Evaluate(s.Params().data(), q.data(), nullptr));
  const double cost = 0.5 * Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()).squaredNorm();
  for (int i = 0; i + 1 < root.num_residuals(); ++i) EXPECT_EQ(q[i], 0.0) << i;
  EXPECT_NEAR(0.5 * q.back() * q.back(), cost, 1e-13 * cost);
  std::vector<std::vector<double>> J(6);
  std::vector<double*> pj(6);
  for (int b = 0; b < 6; ++b) {
    J[b].assign(root.num_residuals() * root.parameter_block_sizes()[b], 0.0);
    pj[b] = J[b].data();
  }
  ASSERT_TRUE(root.Evaluate(s.Params().data(), q.data(), pj.data()));
  EXPECT_GT(Eigen::Map<const Eigen::VectorXd>(q.data(), 36).norm(), 0.0);
  EXPECT_NEAR(0.5 * Eigen::Map<const Eigen::VectorXd>(q.data(), q.size()).squaredNorm(), cost,
              1e-12 * cost);
}

// Every point on one firing: the rows' Jacobians span at most the 6 directions of δT(τ), so JᵀJ
// has rank <= 6 of 36. The square-root form keeps that information and drops the rest (zero rows),
// with the cost, gradient and JᵀJ of the point rows and nothing non-finite.
TEST(ContinuousPointToPlaneBatch, SquareRootOfARankDeficientBatch) {
  std::mt19937 rng(64);
  const auto model = ctlio::testing::NewerCollegeSingerModel();
  const auto firing = std::make_shared<const SharedPoseInterpolation>(
      std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.04));
  std::vector<ContinuousPointToPlaneBatch::Point> points;
  std::vector<std::unique_ptr<ceres::CostFunction>> owned;
  std::vector<ceres::CostFunction*> singles;
  for (int i = 0; i < 50; ++i) {
    points.push_back({firing, RandomAssociation(rng), Vec3::Zero()});
    owned.push_back(std::make_unique<ContinuousPointToPlane>(firing, points.back().association));
    singles.push_back(owned.back().get());
  }
  ContinuousPointToPlaneBatch root(points, nullptr, false, Form::kSquareRoot);
  const Knots at = WithoutExtrinsic(KnotsOfKind(rng, 0));
  const Evaluated a = EvaluateProblem(singles, nullptr, at);
  const Evaluated b = EvaluateProblem({&root}, nullptr, at);
  ASSERT_TRUE(b.JtJ.allFinite());
  EXPECT_NEAR(b.cost, a.cost, 1e-10 * a.cost);
  const double g_scale =
      Eigen::Map<const Eigen::VectorXd>(a.gradient.data(), 36).cwiseAbs().maxCoeff();
  for (size_t i = 0; i < a.gradient.size(); ++i) {
    EXPECT_NEAR(b.gradient[i], a.gradient[i], 1e-10 * g_scale) << i;
  }
  EXPECT_LE((b.JtJ - a.JtJ).cwiseAbs().maxCoeff(), 1e-10 * a.JtJ.cwiseAbs().maxCoeff());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a.JtJ);
  int rank = 0;
  for (Eigen::Index i = 0; i < 36; ++i) rank += eig.eigenvalues()[i] > 1e-9 * eig.eigenvalues()[35];
  EXPECT_EQ(rank, 6);
}

TEST(ContinuousPointToPlaneBatch, ConvexLossFailsTheEvaluation) {
  std::mt19937 rng(55);
  const ContinuousPointToPlaneBatch batch(RandomPoints(rng, 3),
                                          std::make_shared<const ceres::TolerantLoss>(1.0, 0.5));
  const Knots s = WithoutExtrinsic(KnotsOfKind(rng, 0));
  std::vector<double> r(4);
  EXPECT_FALSE(batch.Evaluate(s.Params().data(), r.data(), nullptr));
  const ContinuousPointToPlaneBatch root(RandomPoints(rng, 3),
                                         std::make_shared<const ceres::TolerantLoss>(1.0, 0.5),
                                         false, Form::kSquareRoot);
  std::vector<double> q(37);
  EXPECT_FALSE(root.Evaluate(s.Params().data(), q.data(), nullptr));
}

// A row runner may split the rows anyhow and run the pieces in any order, on any thread: the
// residuals (the constant row too) and every Jacobian are those of the batch without one, bit for
// bit. The runner here splits its work items unevenly and runs the pieces last first: 40 rows,
// and in square-root form 4 chunks (200 rows); with the extrinsic and with a Cauchy loss; a
// convex loss still fails the evaluation.
void ExpectRunnerGivesTheSameValues(Form form, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  const auto points = RandomPoints(rng, n);
  const auto runner = [](size_t items, const std::function<void(size_t, size_t)>& rows) {
    const std::vector<size_t> cuts = {items, 2 * items / 3, items / 2, 1, 0};
    for (size_t j = 0; j + 1 < cuts.size(); ++j) rows(cuts[j + 1], cuts[j]);
  };
  for (const bool extrinsic : {false, true}) {
    for (const bool robust : {false, true}) {
      SCOPED_TRACE("extrinsic " + std::to_string(extrinsic) + " robust " + std::to_string(robust));
      const auto loss = robust ? std::make_shared<const ceres::CauchyLoss>(2.0) : nullptr;
      const ContinuousPointToPlaneBatch plain(points, loss, extrinsic, form);
      ContinuousPointToPlaneBatch split(points, loss, extrinsic, form);
      split.set_row_runner(runner);
      const Knots k = KnotsOfKind(rng, 0);
      const Knots s = extrinsic ? k : WithoutExtrinsic(k);
      const int m = plain.num_residuals();
      const size_t blocks = plain.parameter_block_sizes().size();
      std::vector<std::vector<double>> Ja(blocks), Jb(blocks);
      std::vector<double*> pa(blocks), pb(blocks);
      for (size_t b = 0; b < blocks; ++b) {
        Ja[b].assign(m * plain.parameter_block_sizes()[b], -1.0);
        Jb[b].assign(m * plain.parameter_block_sizes()[b], -2.0);
        pa[b] = Ja[b].data();
        pb[b] = Jb[b].data();
      }
      std::vector<double> ra(m, -1.0), rb(m, -2.0);
      ASSERT_TRUE(plain.Evaluate(s.Params().data(), ra.data(), pa.data()));
      ASSERT_TRUE(split.Evaluate(s.Params().data(), rb.data(), pb.data()));
      EXPECT_EQ(ra, rb);
      for (size_t b = 0; b < blocks; ++b) EXPECT_EQ(Ja[b], Jb[b]) << "block " << b;
      std::vector<double> r_only(m, -3.0), r_plain(m, -4.0);
      ASSERT_TRUE(split.Evaluate(s.Params().data(), r_only.data(), nullptr));
      ASSERT_TRUE(plain.Evaluate(s.Params().data(), r_plain.data(), nullptr));
      EXPECT_EQ(r_plain, r_only);
      // The point rows are the same with or without Jacobians (the square-root rows are not).
      if (form == Form::kPointRows) EXPECT_EQ(ra, r_only);
    }
  }
  ContinuousPointToPlaneBatch convex(points, std::make_shared<const ceres::TolerantLoss>(1.0, 0.5),
                                     false, form);
  convex.set_row_runner(runner);
  std::vector<double> r(convex.num_residuals());
  EXPECT_FALSE(
      convex.Evaluate(WithoutExtrinsic(KnotsOfKind(rng, 0)).Params().data(), r.data(), nullptr));
}

TEST(ContinuousPointToPlaneBatch, RowRunnerGivesTheSameValuesBitForBit) {
  ExpectRunnerGivesTheSameValues(Form::kPointRows, 40, 56);
}

TEST(ContinuousPointToPlaneBatch, RowRunnerGivesTheSameSquareRootValuesBitForBit) {
  ExpectRunnerGivesTheSameValues(Form::kSquareRoot, 200, 57);
}

TEST(ContinuousPointToPlaneBatch, NoPointsIsAnError) {
  EXPECT_THROW(ContinuousPointToPlaneBatch({}, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio
