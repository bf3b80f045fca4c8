// SlidingWindow: exactness of marginalisation on a linear-Gaussian GP problem (against the full
// batch marginal), agreement of its linearisation with Ceres' own (manifolds + loss functions),
// preservation of the Gauss–Newton model under marginalisation for a mix of manifolds, forgetting
// a state's information in the marginal prior, and the documented edge cases.
#include "ctlio/solvers/sliding_window.h"

#include <gtest/gtest.h>

#include <iostream>
#include <memory>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/vector_prior.h"
#include "ctlio/factors/priors/marginalization_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio {
namespace {

using testing::RandomPose;
using testing::RandomVec6;

Eigen::MatrixXd RandomMatrix(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd A(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) A(i, j) = n(rng);
  return A;
}

// A unary Gaussian on Euclidean blocks: r = A·(x − x̄) (MarginalizationPrior with r0 = 0).
MarginalizationPrior* EuclideanFactor(const Eigen::MatrixXd& A, const Eigen::VectorXd& x_bar) {
  return new MarginalizationPrior({nullptr}, {static_cast<int>(x_bar.size())}, {x_bar.data()}, A,
                                  Eigen::VectorXd::Zero(A.rows()));
}

// r = A·[x₁; x₂; …] on Euclidean blocks of the given sizes (x̄ = 0, r0 = 0).
MarginalizationPrior* LinearMap(const Eigen::MatrixXd& A, const std::vector<int>& sizes) {
  static const std::vector<double> zeros(64, 0.0);
  std::vector<const ceres::Manifold*> manifolds(sizes.size(), nullptr);
  std::vector<const double*> points(sizes.size(), zeros.data());
  return new MarginalizationPrior(manifolds, sizes, points, A, Eigen::VectorXd::Zero(A.rows()));
}

// ---------------------------------------------------------------------------------------------
// Linear-Gaussian 1D GP: knots [p, v, a] with a Singer prior (gp::VectorGpPrior), a Gaussian
// prior on the first knot and noisy position measurements. After every step the window (4 knots,
// oldest marginalised) must reproduce the newest knot's batch marginal mean and covariance.
// ---------------------------------------------------------------------------------------------

struct LinearFactor {
  std::unique_ptr<ceres::CostFunction> cost;  // a twin of the factor given to the window
  std::vector<int> knots;
};

// Dense batch solution of Σ‖r_i(x)‖² (every factor linear): stacks J and r and solves by
// column-pivoted QR (no normal equations, so the reference is accurate to ~1e-13 here).
void BatchSolve(const std::vector<LinearFactor>& factors, int num_knots, Eigen::VectorXd* mean,
                Eigen::MatrixXd* covariance) {
  const int n = 3 * num_knots;
  int rows = 0;
  for (const LinearFactor& f : factors) rows += f.cost->num_residuals();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(rows);
  const double zeros[3] = {0.0, 0.0, 0.0};
  int row = 0;
  for (const LinearFactor& f : factors) {
    const int m = f.cost->num_residuals();
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> blocks(f.knots.size());
    std::vector<double*> jac;
    std::vector<const double*> params;
    for (auto& j : blocks) {
      j.resize(m, 3);
      jac.push_back(j.data());
      params.push_back(zeros);
    }
    ASSERT_TRUE(f.cost->Evaluate(params.data(), r.data() + row, jac.data()));
    for (size_t i = 0; i < f.knots.size(); ++i) J.block(row, 3 * f.knots[i], m, 3) = blocks[i];
    row += m;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J);
  *mean = -qr.solve(r);
  // (JᵀJ)⁻¹ = R⁻¹R⁻ᵀ in the pivoted order.
  const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(n, n).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd R_inv =
      R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::MatrixXd P =
      qr.colsPermutation() * (R_inv * R_inv.transpose()) * qr.colsPermutation().transpose();
  *covariance = P;
}

// The Gauss–Newton step −H⁻¹b of the whole window (Euclidean states, ascending ids).
Eigen::VectorXd NewtonStep(const SlidingWindow& window) {
  std::vector<ceres::ResidualBlockId> all;
  for (StateId id : window.StateIds())
    for (auto r : window.ResidualBlocksOf(id))
      if (std::find(all.begin(), all.end(), r) == all.end()) all.push_back(r);
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  window.Linearize(all, window.StateIds(), &H, &b);
  return -H.ldlt().solve(b);
}

TEST(SlidingWindow, LinearGaussianNewestStateMatchesBatchMarginal) {
  constexpr double kAlpha = 0.7, kQc = 2.0, kDt = 0.1, kSigma = 0.05;
  constexpr int kSteps = 60, kWindow = 4;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);

  SlidingWindowOptions options;
  // A linear problem: near-Gauss–Newton steps and tolerances tight enough for 1e-12 solutions.
  options.solver.initial_trust_region_radius = 1e12;
  options.solver.function_tolerance = 1e-20;
  options.solver.gradient_tolerance = 1e-20;
  options.solver.parameter_tolerance = 1e-20;
  options.solver.max_num_iterations = 20;
  SlidingWindow window(options);

  std::vector<LinearFactor> batch;
  auto add = [&](auto make, std::vector<int> knots) {
    std::vector<StateId> ids(knots.begin(), knots.end());
    window.AddResidualBlock(make(), nullptr, ids);
    batch.push_back({std::unique_ptr<ceres::CostFunction>(make()), knots});
  };

  // Truth: a sampled trajectory (any will do; the test compares estimators, not truth).
  double p = 0.0, v = 1.0;
  const Eigen::Vector3d x0(0.0, 1.0, 0.0);
  Eigen::Matrix3d W0 = Eigen::Vector3d(1.0 / 0.1, 1.0 / 0.5, 1.0 / 2.0).asDiagonal();
  int marginalizations = 0;
  double worst_mean = 0.0, worst_cov = 0.0;
  for (int k = 0; k < kSteps; ++k) {
    const Eigen::Vector3d guess(p + 0.3 * noise(rng), v, 0.0);  // deliberately off
    window.AddVectorState(k, guess);
    if (k == 0) {
      add([&] { return EuclideanFactor(W0, x0); }, {0});
    } else {
      add([&] { return gp::MakeSingerPrior1D(kAlpha, kQc, kDt); }, {k - 1, k});
    }
    const double y = p + kSigma * noise(rng);
    Eigen::Matrix<double, 1, 3> H;
    H << 1.0 / kSigma, 0.0, 0.0;
    add([&] { return EuclideanFactor(H, Eigen::Vector3d(y, 0.0, 0.0)); }, {k});
    p += v * kDt + 0.5 * std::sin(0.3 * k) * kDt * kDt;
    v += std::sin(0.3 * k) * kDt;

    const ceres::Solver::Summary summary = window.Solve();
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    if (window.num_states() > kWindow) {
      const MarginalizationReport report = window.Marginalize({window.StateIds().front()});
      EXPECT_EQ(report.kept.size(), 1u);
      EXPECT_EQ(report.prior_rank, 3);
      EXPECT_EQ(report.marginalized_rank, 3);
      ++marginalizations;
    }
    Eigen::VectorXd mean;
    Eigen::MatrixXd P;
    BatchSolve(batch, k + 1, &mean, &P);
    // Ceres stops when the cost no longer changes in floating point, which in this problem's
    // weakest directions (posterior σ ~ 1) leaves ~1e-7 in the estimate. The exact minimiser of
    // the window's (linear) model is one Newton step away; that is what must equal the batch.
    const Eigen::Vector3d solved = window.Vector(k);
    const Eigen::Vector3d window_mean = solved + NewtonStep(window).tail<3>();
    EXPECT_LT((solved - window_mean).cwiseAbs().maxCoeff(), 1e-5);
    const Eigen::Matrix3d window_cov = window.Covariance({k});
    const Eigen::Matrix3d batch_cov = P.bottomRightCorner<3, 3>();
    const double mean_error = (window_mean - mean.tail<3>()).cwiseAbs().maxCoeff();
    const double cov_error =
        (window_cov - batch_cov).cwiseAbs().maxCoeff() / batch_cov.cwiseAbs().maxCoeff();
    EXPECT_LT(mean_error, 1e-9) << "step " << k;
    EXPECT_LT(cov_error, 1e-9) << "step " << k;
    worst_mean = std::max(worst_mean, mean_error);
    worst_cov = std::max(worst_cov, cov_error);
  }
  std::cout << "worst |mean error| " << worst_mean << ", worst relative covariance error "
            << worst_cov << "\n";
  EXPECT_EQ(marginalizations, kSteps - kWindow);
  EXPECT_EQ(window.num_states(), kWindow);
  // Window: 3 priors + 4 measurements + the marginalisation prior.
  EXPECT_EQ(window.num_residual_blocks(), 2 * kWindow);
}

// ---------------------------------------------------------------------------------------------
// Mixed manifolds: a pose, a rotation (e.g. gravity) and vectors, coupled by nonlinear factors
// (MarginalizationPrior with random A and x̄ is nonlinear in poses and rotations) with losses.
// ---------------------------------------------------------------------------------------------

struct MixedProblem {
  // ids: 0, 1, 2 poses; 10 rotation; 20, 21 vectors (6 and 3)
  std::vector<std::unique_ptr<ceres::CostFunction>> twins;
};

void BuildMixed(SlidingWindow* window, std::mt19937& rng, bool with_losses) {
  window->AddPoseState(0, RandomPose(rng, 2.0, 3.0));
  window->AddPoseState(1, RandomPose(rng, 2.0, 3.0));
  window->AddPoseState(2, RandomPose(rng, 2.0, 3.0));
  window->AddRotationState(10, RandomPose(rng, 3.0, 0.0).rotation());
  window->AddVectorState(20, RandomVec6(rng, 1.0));
  window->AddVectorState(21, Eigen::Vector3d(0.1, 0.2, 0.3));
  const PoseManifold pose;
  const RotationManifold rotation;
  auto factor = [&](const std::vector<StateId>& ids, int rows, ceres::LossFunction* loss) {
    std::vector<const ceres::Manifold*> manifolds;
    std::vector<int> sizes;
    std::vector<std::vector<double>> points;
    int tangent = 0;
    for (StateId id : ids) {
      manifolds.push_back(window->Manifold(id));
      sizes.push_back(window->AmbientSize(id));
      tangent += window->TangentSize(id);
      // Linearisation points away from the current values: nonlinear residuals.
      std::vector<double> x(window->AmbientSize(id));
      const Eigen::VectorXd delta = 0.8 * RandomMatrix(rng, window->TangentSize(id), 1);
      if (window->Manifold(id) == nullptr) {
        for (int i = 0; i < window->AmbientSize(id); ++i) x[i] = window->State(id)[i] + delta[i];
      } else {
        window->Manifold(id)->Plus(window->State(id), delta.data(), x.data());
      }
      points.push_back(x);
    }
    std::vector<const double*> p;
    for (const auto& x : points) p.push_back(x.data());
    window->AddResidualBlock(
        new MarginalizationPrior(manifolds, sizes, p, RandomMatrix(rng, rows, tangent),
                                 RandomMatrix(rng, rows, 1)),
        loss, ids);
  };
  factor({0}, 6, nullptr);
  factor({0, 1, 20}, 9, with_losses ? new ceres::HuberLoss(0.5) : nullptr);
  factor({1, 2, 10}, 8, with_losses ? new ceres::CauchyLoss(1.0) : nullptr);
  factor({2, 20, 21}, 7, nullptr);
  factor({10, 21}, 3, with_losses ? new ceres::SoftLOneLoss(0.3) : nullptr);
  factor({2}, 6, nullptr);
  factor({0, 10}, 9, nullptr);
  factor({1}, 6, nullptr);
  factor({21}, 3, nullptr);
  (void)pose;
  (void)rotation;
}

// The window's linearisation (tangent Jacobians, Triggs-corrected losses) equals the Gauss–Newton
// model Ceres itself builds (Problem::Evaluate returns tangent-space Jacobians).
TEST(SlidingWindow, LinearizationMatchesCeresGaussNewtonModel) {
  std::mt19937 rng(3);
  SlidingWindow window;
  BuildMixed(&window, rng, /*with_losses=*/true);
  const std::vector<StateId> ids = window.StateIds();
  std::vector<ceres::ResidualBlockId> residuals;
  for (StateId id : ids)
    for (auto r : window.ResidualBlocksOf(id))
      if (std::find(residuals.begin(), residuals.end(), r) == residuals.end())
        residuals.push_back(r);
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  window.Linearize(residuals, ids, &H, &b);

  ceres::Problem::EvaluateOptions eval;
  for (StateId id : ids) eval.parameter_blocks.push_back(window.State(id));
  eval.residual_blocks = residuals;
  std::vector<double> residual_values, gradient;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(window.problem().Evaluate(eval, nullptr, &residual_values, &gradient, &crs));
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i)
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  ASSERT_EQ(J.cols(), H.cols());
  const Eigen::MatrixXd H_ceres = J.transpose() * J;
  const Eigen::VectorXd g_ceres = Eigen::Map<Eigen::VectorXd>(gradient.data(), gradient.size());
  EXPECT_LT((H - H_ceres).norm(), 1e-12 * H_ceres.norm());
  EXPECT_LT((b - g_ceres).norm(), 1e-12 * g_ceres.norm());
}

// Marginalising at the current estimate must not change the Gauss–Newton model of the states that
// stay: their joint covariance before and after is identical. Several states at once, mixed
// manifolds, losses.
TEST(SlidingWindow, MarginalizationPreservesMarginalOfKeptStates) {
  for (bool with_losses : {false, true}) {
    std::mt19937 rng(4);
    SlidingWindow window;
    BuildMixed(&window, rng, with_losses);
    const std::vector<StateId> kept = {1, 2, 10, 21};
    const Eigen::MatrixXd before = window.Covariance(kept);
    // The comparison is meaningful only if the window is well posed.
    const Eigen::VectorXd eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(before).eigenvalues();
    ASSERT_GT(eigenvalues.minCoeff(), 1e-8 * eigenvalues.maxCoeff());
    const MarginalizationReport report = window.Marginalize({0, 20});
    EXPECT_EQ(report.marginalized, (std::vector<StateId>{0, 20}));
    EXPECT_EQ(report.kept, (std::vector<StateId>{1, 2, 10, 21}));
    EXPECT_EQ(report.removed_residual_blocks, 4);
    EXPECT_EQ(report.marginalized_dimension, 12);
    EXPECT_EQ(report.marginalized_rank, 12);
    // Kept coordinates 6 + 6 + 3 + 3 = 18, but states 2 and 21 (9 coordinates) only meet the
    // leaving ones through one 7-row factor: at most 18 − 2 directions reach the prior.
    EXPECT_GT(report.prior_rank, 0);
    EXPECT_LE(report.prior_rank, 16);
    EXPECT_FALSE(window.HasState(0));
    EXPECT_FALSE(window.HasState(20));
    EXPECT_EQ(window.num_residual_blocks(), 9 - 4 + 1);
    const Eigen::MatrixXd after = window.Covariance(kept);
    EXPECT_LT((after - before).norm(), 1e-9 * before.norm()) << "losses " << with_losses;
    // And the window still solves.
    EXPECT_TRUE(window.Solve().IsSolutionUsable());
    EXPECT_TRUE(window.Covariance(kept).allFinite());
  }
}

// Marginalising {0, 20} at once equals marginalising 0 then 20 (same linearisation points).
TEST(SlidingWindow, JointEqualsSequentialMarginalization) {
  std::mt19937 rng_a(5), rng_b(5);
  SlidingWindow joint, sequential;
  BuildMixed(&joint, rng_a, true);
  BuildMixed(&sequential, rng_b, true);
  joint.Marginalize({20, 0});
  sequential.Marginalize({0});
  sequential.Marginalize({20});
  const std::vector<StateId> kept = {1, 2, 10, 21};
  const Eigen::MatrixXd a = joint.Covariance(kept);
  const Eigen::MatrixXd b = sequential.Covariance(kept);
  EXPECT_LT((a - b).norm(), 1e-9 * a.norm());
  EXPECT_EQ(joint.num_residual_blocks(), sequential.num_residual_blocks());
}

// ForgetInformation: the marginal prior on {1, 2, 10, 21} forgets 10 (its Schur complement over
// 10: the others' marginal); the caller's factors on 10 (MarginalizationPriors too) stay.
TEST(SlidingWindow, ForgetInformationLeavesTheOtherStatesTheirMarginal) {
  std::mt19937 rng(6);
  SlidingWindow window;
  BuildMixed(&window, rng, true);
  const MarginalizationReport marginalized = window.Marginalize({0, 20});
  ASSERT_EQ(window.StatesOf(marginalized.prior), (std::vector<StateId>{1, 2, 10, 21}));
  Eigen::MatrixXd H, H_after;
  Eigen::VectorXd b, b_after;
  window.Linearize({marginalized.prior}, {10, 1, 2, 21}, &H, &b);
  const SchurComplementResult expected = SchurComplementLeading(H, b, 3);
  const int blocks = window.num_residual_blocks();
  const size_t on_state_10 = window.ResidualBlocksOf(10).size();
  const MarginalizationReport forgot = window.ForgetInformation({10});
  EXPECT_EQ(forgot.marginalized, (std::vector<StateId>{10}));
  EXPECT_EQ(forgot.kept, (std::vector<StateId>{1, 2, 21}));
  EXPECT_EQ(forgot.removed_residual_blocks, 1);
  EXPECT_EQ(forgot.marginalized_rank, 3);
  ASSERT_NE(forgot.prior, nullptr);
  EXPECT_EQ(window.num_residual_blocks(), blocks);  // one prior for one
  EXPECT_EQ(window.ResidualBlocksOf(10).size(), on_state_10 - 1);
  window.Linearize({forgot.prior}, {1, 2, 21}, &H_after, &b_after);
  EXPECT_LT((H_after - expected.information).norm(), 1e-9 * expected.information.norm());
  EXPECT_LT((b_after - expected.vector).norm(), 1e-9 * (1.0 + expected.vector.norm()));
  EXPECT_TRUE(window.Solve().IsSolutionUsable());
  // No marginal prior on 10 left (the caller's factors are not the window's): nothing changes.
  const MarginalizationReport again = window.ForgetInformation({10});
  EXPECT_EQ(again.removed_residual_blocks, 0);
  EXPECT_EQ(again.prior, nullptr);
  EXPECT_EQ(window.num_residual_blocks(), blocks);
  EXPECT_THROW(window.ForgetInformation({}), std::invalid_argument);
  EXPECT_THROW(window.ForgetInformation({99}), std::invalid_argument);
  EXPECT_THROW(window.ForgetInformation({1, 1}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Edge cases and bad input.
// ---------------------------------------------------------------------------------------------

TEST(SlidingWindow, EmptyWindowAndUnknownStatesThrow) {
  SlidingWindow window;
  EXPECT_THROW(window.Solve(), std::logic_error);
  EXPECT_THROW(window.Marginalize({1}), std::logic_error);
  window.AddVectorState(1, Eigen::Vector3d::Zero());
  EXPECT_THROW(window.Marginalize({}), std::invalid_argument);
  EXPECT_THROW(window.Marginalize({1, 1}), std::invalid_argument);
  try {
    window.Marginalize({7});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown state id 7"), std::string::npos) << what;
    EXPECT_NE(what.find("sliding_window.cc"), std::string::npos) << what;
  }
  EXPECT_TRUE(window.HasState(1));
  EXPECT_THROW(window.Covariance({7}), std::invalid_argument);
  EXPECT_THROW(window.State(7), std::invalid_argument);
  EXPECT_THROW(window.AddVectorState(1, Eigen::Vector3d::Zero()), std::invalid_argument);
}

TEST(SlidingWindow, RejectsBadStatesAndResiduals) {
  SlidingWindow window;
  const double x[6] = {0, 0, 0, 0, 0, 0};
  EXPECT_THROW(window.AddState(1, x, 6, std::make_shared<ceres::EuclideanManifold<6>>()),
               std::invalid_argument);
  EXPECT_THROW(window.AddState(1, x, 3, std::make_shared<RotationManifold>()),
               std::invalid_argument);  // size does not fit the manifold
  const double nan[2] = {0.0, std::numeric_limits<double>::quiet_NaN()};
  EXPECT_THROW(window.AddState(2, nan, 2), std::invalid_argument);
  window.AddVectorState(3, Eigen::Vector3d::Zero());
  window.AddVectorState(4, Eigen::Vector2d::Zero());
  auto* f = EuclideanFactor(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  EXPECT_THROW(window.AddResidualBlock(f, nullptr, {4}), std::invalid_argument);     // size
  EXPECT_THROW(window.AddResidualBlock(f, nullptr, {3, 4}), std::invalid_argument);  // count
  EXPECT_THROW(window.AddResidualBlock(f, nullptr, {9}), std::invalid_argument);     // unknown
  window.AddResidualBlock(f, nullptr, {3});  // takes ownership only on success
  EXPECT_EQ(window.num_residual_blocks(), 1);
}

// A state nothing is connected to is removed exactly (no information is lost) and no prior is
// added; marginalising every state empties the window.
TEST(SlidingWindow, DisconnectedStateIsRemovedWithoutPrior) {
  SlidingWindow window;
  window.AddVectorState(1, Eigen::Vector3d(1, 2, 3));
  window.AddVectorState(2, Eigen::Vector3d(4, 5, 6));
  window.AddResidualBlock(EuclideanFactor(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
                          nullptr, {2});
  MarginalizationReport report = window.Marginalize({1});
  EXPECT_TRUE(report.kept.empty());
  EXPECT_EQ(report.prior_rank, 0);
  EXPECT_EQ(report.prior, nullptr);
  EXPECT_EQ(report.removed_residual_blocks, 0);
  EXPECT_EQ(window.num_states(), 1);
  EXPECT_EQ(window.num_residual_blocks(), 1);
  report = window.Marginalize({2});  // connected to nothing else: removed with its residual
  EXPECT_EQ(report.removed_residual_blocks, 1);
  EXPECT_EQ(report.prior_rank, 0);
  EXPECT_EQ(window.num_states(), 0);
  EXPECT_EQ(window.num_residual_blocks(), 0);
}

// A marginalised state whose information block is singular (one coordinate unobserved, two
// others observed only through their sum): the pseudo-inverse gives a finite prior with the
// rank the data support, the window still solves, nothing is NaN.
TEST(SlidingWindow, SingularMarginalBlockGivesFinitePrior) {
  SlidingWindow window;
  window.AddVectorState(1, Eigen::Vector3d(0.5, -0.2, 0.1));
  window.AddVectorState(2, Eigen::Vector2d(0.3, 0.4));
  // Factor on (1, 2): r = [x1₀ + x1₁ − x2₀; x2₁ − 1]: x1₂ never observed, x1₀/x1₁ only summed.
  Eigen::MatrixXd A(2, 5);
  A << 1, 1, 0, -1, 0, 0, 0, 0, 0, 1;
  Eigen::VectorXd x_bar(5);
  x_bar << 0, 0, 0, 0, 1;
  const double* p1 = x_bar.data();
  const double* p2 = x_bar.data() + 3;
  window.AddResidualBlock(
      new MarginalizationPrior({nullptr, nullptr}, {3, 2}, {p1, p2}, A, Eigen::VectorXd::Zero(2)),
      nullptr, {1, 2});
  window.AddResidualBlock(
      EuclideanFactor(Eigen::Matrix2d::Identity() * 10.0, Eigen::Vector2d(0.0, 0.0)), nullptr, {2});
  const MarginalizationReport report = window.Marginalize({1});
  EXPECT_EQ(report.marginalized_dimension, 3);
  EXPECT_EQ(report.marginalized_rank, 1);
  // x1₀ + x1₁ absorbs the first row entirely; only the second row reaches state 2.
  EXPECT_EQ(report.prior_rank, 1);
  const auto* prior = dynamic_cast<const MarginalizationPrior*>(
      window.problem().GetCostFunctionForResidualBlock(report.prior));
  ASSERT_NE(prior, nullptr);
  EXPECT_TRUE(prior->sqrt_information().allFinite());
  EXPECT_TRUE(prior->r0().allFinite());
  EXPECT_TRUE(window.Solve().IsSolutionUsable());
  const Eigen::Matrix2d P = window.Covariance({2});
  EXPECT_TRUE(P.allFinite());
  // x2₀: only the measurement (σ = 0.1); x2₁: measurement and the unit row.
  EXPECT_NEAR(P(0, 0), 0.01, 1e-12);
  EXPECT_NEAR(P(1, 1), 1.0 / 101.0, 1e-12);
}

// A residual that is NaN at the current estimate: clear error, window unchanged.
class NanCost final : public ceres::SizedCostFunction<1, 2> {
 public:
  bool Evaluate(double const* const*, double* residuals, double** jacobians) const override {
    residuals[0] = std::numeric_limits<double>::quiet_NaN();
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = jacobians[0][1] = 0.0;
    return true;
  }
};

TEST(SlidingWindow, NonFiniteResidualThrowsAndLeavesWindowUnchanged) {
  SlidingWindow window;
  window.AddVectorState(1, Eigen::Vector2d::Zero());
  window.AddVectorState(2, Eigen::Vector2d::Zero());
  window.AddResidualBlock(new NanCost, nullptr, {1});
  window.AddResidualBlock(LinearMap(Eigen::MatrixXd::Identity(2, 4), {2, 2}), nullptr, {1, 2});
  EXPECT_THROW(window.Marginalize({1}), std::runtime_error);
  EXPECT_EQ(window.num_states(), 2);
  EXPECT_EQ(window.num_residual_blocks(), 2);
}

TEST(SlidingWindow, RemoveStateDropsItsResiduals) {
  SlidingWindow window;
  window.AddVectorState(1, Eigen::Vector2d::Zero());
  window.AddVectorState(2, Eigen::Vector2d::Zero());
  window.AddResidualBlock(LinearMap(Eigen::MatrixXd::Identity(4, 4), {2, 2}), nullptr, {1, 2});
  window.AddResidualBlock(EuclideanFactor(Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero()),
                          nullptr, {2});
  window.RemoveState(1);
  EXPECT_EQ(window.num_residual_blocks(), 1);
  EXPECT_TRUE(window.ResidualBlocksOf(2).size() == 1);
}

}  // namespace
}  // namespace ctlio
