// The χ² bookkeeping of the IMU consistency check (imu_consistency.h) on tiny problems whose
// residuals are known exactly: only the listed blocks count, the robust loss is not applied, the
// accelerometer and gyro sums and counts are kept apart, and the problem's EvaluationCallback
// runs first (the Singer-LIO IMU residuals read the state it interpolates).
#include "ctlio/solvers/lio/imu_consistency.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace ctlio::lio {
namespace {

// r = x − c, N components of one N-vector.
template <int N>
class Offset final : public ceres::SizedCostFunction<N, N> {
 public:
  explicit Offset(std::vector<double> c) : c_(std::move(c)) {}
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    for (int i = 0; i < N; ++i) r[i] = p[0][i] - c_[i];
    if (J != nullptr && J[0] != nullptr) {
      for (int i = 0; i < N * N; ++i) J[0][i] = (i % (N + 1) == 0) ? 1.0 : 0.0;
    }
    return true;
  }

 private:
  std::vector<double> c_;
};

// r = *prepared: a value the evaluation callback writes, as SharedInterpolationCallback prepares
// the interpolated state the IMU residuals read.
class Prepared final : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit Prepared(const double* value) : value_(value) {}
  bool Evaluate(double const* const*, double* r, double** J) const override {
    r[0] = *value_;
    if (J != nullptr && J[0] != nullptr) J[0][0] = 0.0;
    return true;
  }

 private:
  const double* value_;
};

class DoubleX final : public ceres::EvaluationCallback {
 public:
  DoubleX(const double* x, double* out) : x_(x), out_(out) {}
  void PrepareForEvaluation(bool, bool) override { *out_ = 2.0 * *x_; }

 private:
  const double* x_;
  double* out_;
};

TEST(ImuConsistency, ChiSquareOfTheListedBlocksWithoutTheLoss) {
  double a[3] = {1.0, 2.0, 3.0}, g[2] = {0.5, -0.5}, other[1] = {10.0};
  ceres::Problem problem;
  ImuTermBlocks blocks;
  // Accelerometer: residuals (1, 2, 3) − (0, 0, 1) = (1, 2, 2): 9, under a Cauchy loss that would
  // give ρ(9) = log(10) = 2.30 instead.
  blocks.accel.push_back(
      problem.AddResidualBlock(new Offset<3>({0.0, 0.0, 1.0}), new ceres::CauchyLoss(1.0), a));
  // A second one on the same block: (1, 2, 3) − (1, 2, 0) = (0, 0, 3): 9.
  blocks.accel.push_back(problem.AddResidualBlock(new Offset<3>({1.0, 2.0, 0.0}), nullptr, a));
  // Gyro: (0.5, −0.5) − (0, 0.5) = (0.5, −1): 1.25.
  blocks.gyro.push_back(problem.AddResidualBlock(new Offset<2>({0.0, 0.5}), nullptr, g));
  // Not an IMU block (a lidar residual, say): r = 10, must not count.
  problem.AddResidualBlock(new Offset<1>({0.0}), nullptr, other);

  ChiSquare accel, gyro;
  EvaluateImuChiSquare(&problem, blocks, &accel, &gyro);
  EXPECT_DOUBLE_EQ(accel.chi2, 18.0);
  EXPECT_EQ(accel.dof, 6);
  EXPECT_DOUBLE_EQ(gyro.chi2, 1.25);
  EXPECT_EQ(gyro.dof, 2);

  // At new values (after a solve, say) the χ² follows them.
  a[2] = 1.0;  // (1, 2, 0) and (0, 0, 1): 5 + 1
  EvaluateImuChiSquare(&problem, blocks, &accel, &gyro);
  EXPECT_DOUBLE_EQ(accel.chi2, 6.0);

  // Gyro only (lidar_gyro) and none at all (lidar_only).
  EvaluateImuChiSquare(&problem, {{}, blocks.gyro}, &accel, &gyro);
  EXPECT_EQ(accel.dof, 0);
  EXPECT_EQ(accel.chi2, 0.0);
  EXPECT_DOUBLE_EQ(gyro.chi2, 1.25);
  EvaluateImuChiSquare(&problem, {}, &accel, &gyro);
  EXPECT_EQ(accel.dof + gyro.dof, 0);
  EXPECT_EQ(accel.chi2 + gyro.chi2, 0.0);
}

TEST(ImuConsistency, TheEvaluationCallbackRunsFirst) {
  double x[1] = {3.0};
  double prepared = 0.0;  // stale until the callback runs
  DoubleX callback(x, &prepared);
  ceres::Problem::Options options;
  options.evaluation_callback = &callback;
  ceres::Problem problem(options);
  ImuTermBlocks blocks;
  blocks.gyro.push_back(problem.AddResidualBlock(new Prepared(&prepared), nullptr, x));
  ChiSquare accel, gyro;
  EvaluateImuChiSquare(&problem, blocks, &accel, &gyro);
  EXPECT_DOUBLE_EQ(gyro.chi2, 36.0);  // (2·3)²
  x[0] = -1.0;
  EvaluateImuChiSquare(&problem, blocks, &accel, &gyro);
  EXPECT_DOUBLE_EQ(gyro.chi2, 4.0);
}

TEST(ImuConsistency, ANonFiniteResidualGivesNaNWithTheCountsKept) {
  double a[1] = {std::numeric_limits<double>::infinity()};
  ceres::Problem problem;
  ImuTermBlocks blocks;
  blocks.accel.push_back(problem.AddResidualBlock(new Offset<1>({0.0}), nullptr, a));
  ChiSquare accel, gyro;
  EvaluateImuChiSquare(&problem, blocks, &accel, &gyro);
  EXPECT_TRUE(std::isnan(accel.chi2));
  EXPECT_EQ(accel.dof, 1);
}

}  // namespace
}  // namespace ctlio::lio
