// The lidar error floor of the pose covariance (lidar_floor_covariance.h) on cases with a known
// answer: the floored information of (1), the covariance of a linear-Gaussian pose whose "scan"
// shares a rigid error in the robot frame, and the NEES of such scans' mean over many draws.
#include "ctlio/solvers/lio/lidar_floor_covariance.h"

#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <random>

#include "ctlio/factors/priors/linear_measurement.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/pose_covariance.h"

namespace ctlio::lio {
namespace {

SE3 FarPose() { return SE3::Exp((Vec6() << 5.0, -3.0, 2.0, 0.4, -0.7, 1.1).finished()); }

Mat6 RandomSpd(std::mt19937* rng, double scale) {
  std::normal_distribution<double> n;
  Mat6 A;
  for (int i = 0; i < 36; ++i) A.data()[i] = n(*rng);
  return scale * (A * A.transpose() + 0.5 * Mat6::Identity());
}

TEST(FlooredInformation, IsTheInformationOfTheSummedCovariance) {
  std::mt19937 rng(11);
  const Mat6 H = RandomSpd(&rng, 1e4), F = RandomSpd(&rng, 1e-5);
  const Mat6 expected = (H.inverse() + F).inverse();
  EXPECT_LT((FlooredInformation(H, F) - expected).norm(), 1e-9 * expected.norm());
  // No floor: the information itself.
  EXPECT_LT((FlooredInformation(H, Mat6::Zero()) - H).norm(), 1e-12 * H.norm());
  // A rank-deficient scan (no information along x) and a floor on rotation only: still (1),
  // nothing along x, translation along y z untouched where the floor does not couple.
  Mat6 H2 = Mat6::Zero();
  H2.diagonal() << 0.0, 4e4, 4e4, 1e6, 1e6, 1e6;
  const Vec6 f = (Vec6() << 0, 0, 0, 1e-6, 1e-6, 1e-6).finished();
  const Mat6 G = FlooredInformation(H2, f.asDiagonal());
  EXPECT_NEAR(G(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(G(1, 1), 4e4, 1e-6);
  EXPECT_NEAR(G(3, 3), 1.0 / (1e-6 + 1e-6), 1e-3);  // (1/H + f)⁻¹ per axis
}

// A pose under a "lidar" group (two pose measurements, on this pose alone) and another prior:
// Σ = (P_o⁻¹ + (c·P_l + Ad(T)·Σ_c·Ad(T)ᵀ)⁻¹)⁻¹ in ε, the floor Σ_c being in the robot frame.
TEST(FlooredLidarPoseCovariance, IsTheLinearGaussianCovariance) {
  const SE3 T = FarPose();
  std::mt19937 rng(4);
  const Mat6 P1 = RandomSpd(&rng, 1e-4), P2 = RandomSpd(&rng, 2e-4), Po = RandomSpd(&rng, 1e-3);
  SlidingWindow window;
  window.AddPoseState(0, T);
  const auto a = window.AddResidualBlock(PosePrior::FromCovariance(T, P1), nullptr, {0});
  const auto b = window.AddResidualBlock(PosePrior::FromCovariance(T, P2), nullptr, {0});
  window.AddResidualBlock(PosePrior::FromCovariance(T, Po), nullptr, {0});
  const double c = 0.2;
  const Vec6 floor_sigma = (Vec6() << 0.003, 0.003, 0.003, 0.002, 0.002, 0.002).finished();
  // The baseline's convention: the stored pose is T_mr, tangent_from_body = Ad(T).
  const auto S = FlooredLidarPoseCovariance(window, 0, {a, b}, c, floor_sigma, T, T.Adjoint());
  ASSERT_TRUE(S.has_value());
  const Mat6 P_l = (P1.inverse() + P2.inverse()).inverse();
  const Mat6 floor_eps =
      T.Adjoint() * Mat6(floor_sigma.cwiseAbs2().asDiagonal()) * T.Adjoint().transpose();
  const Mat6 expected = (Po.inverse() + (c * P_l + floor_eps).inverse()).inverse();
  EXPECT_LT((*S - expected).norm(), 1e-8 * expected.norm());
  // Without a floor and at c = 1: ceres::Covariance's.
  const auto S1 = FlooredLidarPoseCovariance(window, 0, {a, b}, 1.0, Vec6::Zero(), T, T.Adjoint());
  const std::optional<Mat6> C = PoseCovariance(&window.problem(), window.State(0), T, T.Adjoint());
  ASSERT_TRUE(S1.has_value() && C.has_value());
  EXPECT_LT((*S1 - *C).norm(), 1e-8 * C->norm());
  // The floor read in the map frame instead would be a different answer (the test can fail).
  const Mat6 wrong =
      (Po.inverse() + (c * P_l + Mat6(floor_sigma.cwiseAbs2().asDiagonal())).inverse()).inverse();
  EXPECT_GT((*S - wrong).norm(), 1e-3 * expected.norm());
}

// Each draw: a "scan" of 40 pose measurements sharing one rigid error η ~ N(0, Σ_c) in the robot
// frame plus independent noise ν_k ~ N(0, P); the estimator weighs each with P (as configured,
// the shared error unknown to it) under a negligible prior, so its estimate is the scan's mean
// and its true covariance Ad(T)·Σ_c·Ad(T)ᵀ + P/40 in ε — what the floor reports. Mean NEES over
// 400 draws: 6 ± 0.6 (χ²₆/400: σ 0.17); without the floor (P/40 alone) it is far above.
TEST(FlooredLidarPoseCovariance, ScansSharingARigidErrorHaveConsistentNees) {
  const SE3 truth = FarPose();
  const Mat6 P = (Vec6() << 4e-4, 4e-4, 4e-4, 1e-5, 1e-5, 1e-5).finished().asDiagonal();
  const Vec6 floor_sigma = (Vec6() << 0.005, 0.005, 0.005, 0.0015, 0.0015, 0.0015).finished();
  const Mat6 L = P.llt().matrixL();
  std::mt19937 rng(7);
  std::normal_distribution<double> n;
  const auto draw = [&] {
    Vec6 z;
    for (int i = 0; i < 6; ++i) z[i] = n(rng);
    return z;
  };
  double nees = 0.0, nees_unfloored = 0.0;
  const int draws = 400;
  for (int d = 0; d < draws; ++d) {
    const Vec6 eta = floor_sigma.cwiseProduct(draw());
    SlidingWindow window;
    window.AddPoseState(0, truth);
    std::vector<ceres::ResidualBlockId> scan;
    for (int k = 0; k < 40; ++k) {
      // The shared error in the robot frame, the independent one in the measurements' own
      // (map-side) tangent: z_k = Exp(ν_k)·truth·Exp(η).
      const SE3 z = SE3::Exp(L * draw()) * truth * SE3::Exp(eta);
      scan.push_back(window.AddResidualBlock(PosePrior::FromCovariance(z, P), nullptr, {0}));
    }
    window.AddResidualBlock(PosePrior::FromCovariance(truth, P * 1e6), nullptr, {0});
    ASSERT_TRUE(window.Solve().IsSolutionUsable());
    const SE3 T = window.Pose(0);
    const auto S = FlooredLidarPoseCovariance(window, 0, scan, 1.0, floor_sigma, T, T.Adjoint());
    const auto S0 = FlooredLidarPoseCovariance(window, 0, scan, 1.0, Vec6::Zero(), T, T.Adjoint());
    ASSERT_TRUE(S.has_value() && S0.has_value());
    const Vec6 e = (truth * T.Inverse()).Log();  // ε of T(true) = Exp(ε)·T, as PoseNees takes it
    nees += e.dot(S->ldlt().solve(e)) / draws;
    nees_unfloored += e.dot(S0->ldlt().solve(e)) / draws;
  }
  EXPECT_NEAR(nees, 6.0, 0.6);
  EXPECT_GT(nees_unfloored, 20.0);
}

// x_b − x_a of two 6-vectors, covariance Q: the motion between two scans' states (test only).
class Difference final : public ceres::SizedCostFunction<6, 6, 6> {
 public:
  explicit Difference(const Mat6& Q) : W_(Mat6(Q.llt().matrixL()).inverse()) {}
  bool Evaluate(double const* const* x, double* r, double** J) const override {
    using Jacobian = Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>;
    Eigen::Map<Vec6> residual(r);
    residual = W_ * (Eigen::Map<const Vec6>(x[1]) - Eigen::Map<const Vec6>(x[0]));
    if (J != nullptr && J[0] != nullptr) Jacobian{J[0]} = -W_;
    if (J != nullptr && J[1] != nullptr) Jacobian{J[1]} = W_;
    return true;
  }

 private:
  Mat6 W_;
};

// A linear chain run as the odometry runs its window (knots: 2, the oldest marginalised before
// each new one): states x_k ∈ R⁶ (T_mr = identity, tangent_from_body = I), a motion
// x_k − x_{k−1} ~ N(0, Q) and a "scan" z_k = x_k + n, n ~ N(0, P_l). The carried covariance is
// the Kalman filter's with the scan's covariance c·P_l + Σ_c at every step; the window's own
// marginal prior, holding the earlier scans at P_l, is not.
TEST(FlooredPoseCovariance, IsTheKalmanFilterOfTheFlooredScans) {
  std::mt19937 rng(9);
  const Mat6 Q = RandomSpd(&rng, 1e-5), P_l = RandomSpd(&rng, 1e-4), P0 = RandomSpd(&rng, 1e-2);
  const double c = 0.3;
  const Vec6 floor_sigma = (Vec6() << 0.004, 0.004, 0.004, 0.003, 0.003, 0.003).finished();
  const Mat6 R = c * P_l + Mat6(floor_sigma.cwiseAbs2().asDiagonal());
  SlidingWindow window;
  FlooredPoseCovariance carried;
  Mat6 P = (P0.inverse() + R.inverse()).inverse();  // the filter after the first scan
  double window_gap = 0.0;
  for (StateId k = 0; k < 8; ++k) {
    if (k > 1) window.Marginalize({k - 2});  // the window keeps the state before the new one
    window.AddVectorState(k, Vec6::Zero());
    if (k == 0) {
      window.AddResidualBlock(LinearMeasurement<6, 6>::Leading(Vec6::Zero(), P0), nullptr, {k});
    } else {
      window.AddResidualBlock(new Difference(Q), nullptr, {k - 1, k});
      P = ((P + Q).inverse() + R.inverse()).inverse();
    }
    const auto scan =
        window.AddResidualBlock(LinearMeasurement<6, 6>::Leading(Vec6::Zero(), P_l), nullptr, {k});
    const auto S = carried.Compute(window, k, {k}, {scan}, c, floor_sigma, SE3(), Mat6::Identity());
    ASSERT_TRUE(S.has_value());
    EXPECT_EQ(carried.used_carried_prior(), k > 0);
    EXPECT_LT((*S - P).norm(), 1e-8 * P.norm()) << "scan " << k;
    const auto W =
        FlooredLidarPoseCovariance(window, k, {scan}, c, floor_sigma, SE3(), Mat6::Identity());
    ASSERT_TRUE(W.has_value());
    window_gap = (*W - P).norm() / P.norm();
  }
  // Flooring the newest scan alone (the window's prior as solved) is a different covariance.
  EXPECT_GT(window_gap, 0.1);
}

}  // namespace
}  // namespace ctlio::lio
