// The numerical core of the 1D study: factors' Jacobians, the square-root chain smoother against
// ceres::Solve + ceres::Covariance, the Kalman-filter likelihood against the dense Gaussian
// likelihood, and heterogeneous preintegration against the batch solution.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/gradient_check.h"
#include "ctlio/solvers/schur_complement.h"
#include "ctlio/study/chain_smoother.h"
#include "ctlio/study/estimators.h"
#include "ctlio/study/imu_input_factor.h"
#include "ctlio/study/measurement_factors.h"
#include "ctlio/study/motion.h"

namespace ctlio::study {
namespace {

SensorConfig ShortSensors(double accel_rate, double duration) {
  SensorConfig s;
  s.duration_s = duration;
  s.accelerometers = {{accel_rate, 0.0, 0.05}};
  return s;
}

TEST(StudyFactors, JacobiansMatchNumeric) {
  const Eigen::Vector2d a(0.3, -1.2), b(0.5, 0.7);
  const Eigen::Vector3d c(0.1, 2.0, -3.0);
  ImuInputPreintegration pre;
  for (int i = 0; i < 5; ++i) pre.Integrate({0.01 + 0.001 * i, 0.3 * i - 0.5, 0.003});
  const ImuInputFactor input(pre);
  EXPECT_TRUE(
      ctlio::testing::JacobiansMatchNumeric(input, {nullptr, nullptr}, {a.data(), b.data()}));
  const ScalarMeasurement<3> accel(2, 0.4, 0.05);
  EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(accel, {nullptr}, {c.data()}));
  Eigen::Matrix3d P;
  P << 2.0, 0.3, 0.1, 0.3, 1.0, -0.2, 0.1, -0.2, 0.5;
  const InitialStatePrior<3> prior(Eigen::Vector3d(1, 2, 3), P);
  EXPECT_TRUE(ctlio::testing::JacobiansMatchNumeric(prior, {nullptr}, {c.data()}));
  // ‖e‖² of the prior is the Mahalanobis distance.
  Eigen::Vector3d r;
  const double* params[] = {c.data()};
  prior.Evaluate(params, r.data(), nullptr);
  const Eigen::Vector3d d = c - Eigen::Vector3d(1, 2, 3);
  EXPECT_NEAR(r.squaredNorm(), d.dot(P.ldlt().solve(d)), 1e-12);
}

TEST(StudyFactors, PreintegrationMatchesSampleBySampleIntegration) {
  // Constant input u over T: Δp = uT²/2, Δv = uT; one piece is rank one and rejected.
  ImuInputPreintegration pre;
  for (int i = 0; i < 4; ++i) pre.Integrate({0.25, 2.0, 1.0});
  EXPECT_NEAR(pre.delta_p(), 1.0, 1e-15);
  EXPECT_NEAR(pre.delta_v(), 2.0, 1e-15);
  // Velocity variance Σ q δ² = 4 · 0.0625.
  EXPECT_NEAR(pre.covariance()(1, 1), 0.25, 1e-15);
  ImuInputPreintegration one;
  one.Integrate({0.1, 1.0, 1.0});
  EXPECT_THROW(ImuInputFactor{one}, std::invalid_argument);
  EXPECT_THROW(one.Integrate({-0.1, 1.0, 1.0}), std::invalid_argument);
}

// Solves the estimator's own Ceres factors with ceres::Solve (DENSE_QR) and ceres::Covariance
// and compares with the chain smoother at every evaluation time.
template <int D>
void CompareWithCeres(const std::vector<std::unique_ptr<ceres::CostFunction>>& factors,
                      const std::vector<std::vector<int>>& states, int num_states,
                      const TrajectoryEstimate& estimate, const std::vector<int>& eval_states) {
  std::vector<Eigen::Matrix<double, D, 1>> x(num_states, Eigen::Matrix<double, D, 1>::Zero());
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  for (size_t f = 0; f < factors.size(); ++f) {
    std::vector<double*> blocks;
    for (int s : states[f]) blocks.push_back(x[s].data());
    problem.AddResidualBlock(factors[f].get(), nullptr, blocks);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.function_tolerance = 1e-16;
  so.gradient_tolerance = 1e-16;
  so.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (int s : eval_states) pairs.emplace_back(x[s].data(), x[s].data());
  ASSERT_TRUE(covariance.Compute(pairs, &problem));
  for (size_t k = 0; k < eval_states.size(); ++k) {
    const auto& xs = x[eval_states[k]];
    EXPECT_LT((estimate.mean[k] - xs).norm(), 1e-8 * (1.0 + xs.norm())) << "state " << k;
    Eigen::Matrix<double, D, D, Eigen::RowMajor> C;
    covariance.GetCovarianceBlock(xs.data(), xs.data(), C.data());
    EXPECT_LT((estimate.covariance[k] - Eigen::MatrixXd(C)).norm(), 1e-7 * C.norm())
        << "state " << k;
  }
}

TEST(ChainSmoother, ImuAsMeasurementEqualsCeresSolveAndCovariance) {
  const SensorConfig sensors = ShortSensors(40.0, 1.0);
  const Trajectory traj = Simulate(WnojDataset(), sensors, 7, 1, 0);
  const ImuAsMeasurement est(MakeSensorModel(WnojDataset(), sensors), PriorConfig{1.3, 0.5});
  std::vector<std::vector<int>> states;
  const auto factors = est.Factors(traj, &states);
  const TrajectoryEstimate smooth = est.Smooth(traj);
  CompareWithCeres<3>(factors, states, static_cast<int>(traj.times_ns.size()), smooth,
                      smooth.nodes);
}

TEST(ChainSmoother, ImuAsInputEqualsCeresSolveAndCovariance) {
  const SensorConfig sensors = ShortSensors(100.0, 1.0);
  const Trajectory traj = Simulate(SingerDataset(), sensors, 7, 1, 0);
  const ImuAsInput est(MakeSensorModel(SingerDataset(), sensors), InputHyperparameters{0.004});
  const InputSchedule schedule = BuildInputSchedule(traj);
  std::vector<std::vector<int>> states;
  const auto factors = est.Factors(traj, schedule, &states);
  const TrajectoryEstimate smooth = est.Smooth(traj, schedule);
  std::vector<int> eval(traj.position.size());
  for (size_t i = 0; i < eval.size(); ++i) eval[i] = static_cast<int>(i);
  CompareWithCeres<2>(factors, states, static_cast<int>(traj.position.size()), smooth, eval);
}

TEST(ChainSmoother, CrossCovarianceMatchesDenseInverse) {
  // Random well-posed chain of 6 states (D = 2): compare against the inverse of JᵀJ.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  const int N = 6;
  ChainSmoother<2> chain(N);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(0, 2 * N);
  Eigen::VectorXd r(0);
  auto append = [&](int first, const ChainSmoother<2>::Rows& rows, bool pair) {
    if (pair) chain.AddPairRows(first, rows);
    const Eigen::Index m = J.rows();
    J.conservativeResize(m + rows.rows(), Eigen::NoChange);
    r.conservativeResize(m + rows.rows());
    J.bottomRows(rows.rows()).setZero();
    J.block(m, 2 * first, rows.rows(), pair ? 4 : 2) = rows.leftCols(pair ? 4 : 2);
    r.tail(rows.rows()) = rows.col(4);
  };
  for (int i = 0; i + 1 < N; ++i) {
    ChainSmoother<2>::Rows rows(3, 5);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 5; ++b) rows(a, b) = n(rng);
    append(i, rows, true);
  }
  // An absolute prior on state 0 through a unary ScalarMeasurement pair.
  const std::vector<Eigen::Vector2d> x(N, Eigen::Vector2d::Zero());
  const ScalarMeasurement<2> m0(0, 0.3, 0.5), m1(1, -0.2, 0.7);
  chain.AddFactor(m0, 0, x);
  chain.AddFactor(m1, 0, x);
  ChainSmoother<2>::Rows unary = ChainSmoother<2>::Rows::Zero(2, 5);
  unary(0, 0) = 2.0;
  unary(0, 4) = -0.6;
  unary(1, 1) = 1.0 / 0.7;
  unary(1, 4) = 0.2 / 0.7;
  append(0, unary, false);
  std::vector<Eigen::Vector2d> delta;
  std::vector<Eigen::Matrix2d> cov, cross;
  chain.Solve(&delta, &cov, &cross);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::MatrixXd Sigma = H.inverse();
  const Eigen::VectorXd dx = -H.ldlt().solve(J.transpose() * r);
  for (int i = 0; i < N; ++i) {
    EXPECT_LT((delta[i] - dx.segment<2>(2 * i)).norm(), 1e-9);
    EXPECT_LT((cov[i] - Sigma.block<2, 2>(2 * i, 2 * i)).norm(), 1e-9);
    if (i + 1 < N) EXPECT_LT((cross[i] - Sigma.block<2, 2>(2 * i, 2 * i + 2)).norm(), 1e-9);
  }
}

TEST(ChainSmoother, UndeterminedStateThrows) {
  ChainSmoother<2> chain(3);  // no factor at all
  std::vector<Eigen::Vector2d> delta;
  EXPECT_THROW(chain.Solve(&delta, nullptr), std::runtime_error);
}

// Dense joint Gaussian of every measurement of estimator 2 (prior propagated state by state),
// whose log-density must equal the Kalman filter's innovation sum.
TEST(KalmanLikelihood, ImuAsMeasurementEqualsDenseGaussian) {
  const SensorConfig sensors = ShortSensors(20.0, 0.5);
  const DatasetConfig data = SingerDataset();
  const Trajectory traj = Simulate(data, sensors, 11, 1, 0);
  const PriorConfig prior{0.7, 3.0};
  const SensorModel model = MakeSensorModel(data, sensors);
  const int n = static_cast<int>(traj.times_ns.size());
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  Eigen::VectorXd mean(3 * n);
  MotionModelCache cache(prior);
  mean.head<3>() = model.x0_mean;
  S.topLeftCorner<3, 3>() = model.p0_variance * Eigen::Matrix3d::Identity();
  for (int k = 0; k + 1 < n; ++k) {
    const auto& m = cache.Get(traj.times_ns[k + 1] - traj.times_ns[k]);
    mean.segment<3>(3 * k + 3) = m.transition * mean.segment<3>(3 * k);
    // Σ_{k+1, j} = Φ Σ_{k, j} for j <= k, then the diagonal block.
    S.block(3 * k + 3, 0, 3, 3 * k + 3) = m.transition * S.block(3 * k, 0, 3, 3 * k + 3);
    S.block(0, 3 * k + 3, 3 * k + 3, 3) = S.block(3 * k + 3, 0, 3, 3 * k + 3).transpose();
    S.block<3, 3>(3 * k + 3, 3 * k + 3) =
        m.transition * S.block<3, 3>(3 * k, 3 * k) * m.transition.transpose() + m.covariance;
  }
  std::vector<int> rows;
  std::vector<double> z, var;
  for (const auto& a : traj.accel[0])
    rows.push_back(3 * a.node + 2), z.push_back(a.value), var.push_back(0.05 * 0.05);
  for (const auto& p : traj.position)
    rows.push_back(3 * p.node), z.push_back(p.value), var.push_back(0.01 * 0.01);
  const int m = static_cast<int>(rows.size());
  Eigen::MatrixXd Z(m, m);
  Eigen::VectorXd nu(m);
  for (int i = 0; i < m; ++i) {
    nu[i] = z[i] - mean[rows[i]];
    for (int j = 0; j < m; ++j) Z(i, j) = S(rows[i], rows[j]) + (i == j ? var[i] : 0.0);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(Z);
  const double logdet = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
  const double dense = -0.5 * (nu.dot(llt.solve(nu)) + logdet + m * std::log(2.0 * M_PI));
  const ImuAsMeasurement est(model, prior);
  EXPECT_NEAR(est.LogLikelihood(traj), dense, 1e-8 * std::abs(dense));
}

TEST(HeterogeneousPreintegration, EqualsBatchAt400Hz) {
  // Two datasets, 2 s at the default rates: the joint factors reproduce the batch solution.
  for (const DatasetConfig& data : {WnojDataset(), SingerDataset()}) {
    const SensorConfig sensors = ShortSensors(400.0, 2.0);
    const Trajectory traj = Simulate(data, sensors, 5, 2, 0);
    const ImuAsMeasurement est(MakeSensorModel(data, sensors), data.prior);
    const TrajectoryEstimate batch = est.Smooth(traj);
    const TrajectoryEstimate het = est.SmoothPreintegrated(traj);
    ASSERT_EQ(batch.nodes, het.nodes);
    for (size_t k = 0; k < batch.nodes.size(); ++k) {
      EXPECT_LT((het.mean[k] - batch.mean[k]).norm(), 1e-9 * (1.0 + batch.mean[k].norm()))
          << data.name << " state " << k;
      EXPECT_LT((het.covariance[k] - batch.covariance[k]).norm(), 1e-9 * batch.covariance[k].norm())
          << data.name << " state " << k;
    }
  }
}

TEST(HeterogeneousPreintegration, InformationFormSchurComplementAgreesAtLowRate) {
  // The dense information-form Schur complement of ctlio/solvers computes the same factor; at a
  // low rate (well-conditioned information) it agrees with the square-root elimination.
  const SensorConfig sensors = ShortSensors(50.0, 2.0);
  const Trajectory traj = Simulate(WnojDataset(), sensors, 5, 2, 1);
  const ImuAsMeasurement est(MakeSensorModel(WnojDataset(), sensors), PriorConfig{1.0, 0.0});
  const TrajectoryEstimate sqrt_form = est.SmoothPreintegrated(traj, false);
  const TrajectoryEstimate info_form = est.SmoothPreintegrated(traj, true);
  for (size_t k = 0; k < sqrt_form.nodes.size(); ++k) {
    EXPECT_LT((info_form.mean[k] - sqrt_form.mean[k]).norm(),
              1e-6 * (1.0 + sqrt_form.mean[k].norm()));
    EXPECT_LT((info_form.covariance[k] - sqrt_form.covariance[k]).norm(),
              1e-6 * sqrt_form.covariance[k].norm());
  }
}

}  // namespace
}  // namespace ctlio::study
