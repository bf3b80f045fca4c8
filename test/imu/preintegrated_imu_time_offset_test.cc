// The preintegrated factor with the IMU clock offset as a state
// (preintegrated_imu_time_offset_factor.h): at δ = δ̄ it is the plain factor; its Jacobians, δ's
// among them, against central differences; and its first-order shift against the interval
// re-integrated over the shifted times (the residual of the true shifted motion falls as d², where
// a wrong rate would leave it at first order).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/factors/imu/preintegrated_imu_time_offset_factor.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::imu {
namespace {

const Vec3 kGravity(0.0, 0.0, -9.81);

ImuNoise Noise() {
  ImuNoise n;
  n.gyro_noise_density = 1.7e-4;
  n.accel_noise_density = 2e-3;
  return n;
}

// A fast handheld-like IMU signal (body rate up to ~3 rad/s, changing within the interval), the
// bias-free readings at time t.
Vec3 Gyro(double t) {
  return Vec3(1.5 * std::sin(3.0 * t) + 0.5, 2.0 * std::cos(2.0 * t), -1.0 + 3.0 * t);
}
Vec3 Accel(double t) {
  return Vec3(2.0 + std::sin(5.0 * t), -1.0 + std::cos(4.0 * t), 9.81 + 2.0 * std::sin(3.0 * t));
}

// The readings (plus the bias b̄) over [a, b], held over steps of h at their midpoints.
PreintegratedImu Preintegrate(double a, double b, const Vec6& bias_hat, double h = 1e-5) {
  PreintegratedImu pim(bias_hat, Noise());
  const int n = static_cast<int>(std::lround((b - a) / h));
  for (int k = 0; k < n; ++k) {
    const double t = a + (k + 0.5) * h;
    pim.Integrate(Accel(t) + bias_hat.head<3>(), Gyro(t) + bias_hat.tail<3>(), h);
  }
  return pim;
}

PreintegrationEnds Ends(double a, double b, const Vec6& bias_hat) {
  PreintegrationEnds e;
  e.accel_begin = Accel(a) + bias_hat.head<3>();
  e.gyro_begin = Gyro(a) + bias_hat.tail<3>();
  e.accel_end = Accel(b) + bias_hat.head<3>();
  e.gyro_end = Gyro(b) + bias_hat.tail<3>();
  return e;
}

struct States {
  std::vector<double> pi, pj;
  Vec3 vi, vj;
  Vec6 b;
};

// State i given; state j predicted from it through `pim` (the true end of that interval).
States Through(const PreintegratedImu& pim, const SE3& Ti, const Vec3& vi) {
  const NavState start{Ti.rotation(), Ti.translation(), vi};
  const NavState end = pim.Predict(start, pim.bias_hat(), kGravity);
  return {testing::PoseParameters(Ti), testing::PoseParameters(SE3(end.C, end.p)), vi, end.v,
          pim.bias_hat()};
}

TEST(PreintegratedImuTimeOffsetFactor, AtTheAnchorItIsThePlainFactor) {
  std::mt19937 rng(5);
  const Vec6 bias_hat = testing::RandomVec6(rng, 0.05);
  const PreintegratedImu pim = Preintegrate(0.3, 0.4, bias_hat, 1e-3);
  const PreintegratedImuFactor plain(pim, kGravity);
  const double anchor = 0.0123;
  const PreintegratedImuTimeOffsetFactor shifted(pim, kGravity, Ends(0.3, 0.4, bias_hat), anchor);
  std::vector<double> pi = testing::PoseParameters(testing::RandomPose(rng, 2.0, 3.0));
  std::vector<double> pj = testing::PoseParameters(testing::RandomPose(rng, 2.0, 3.0));
  Vec3 vi = testing::RandomVec6(rng, 2.0).head<3>(), vj = testing::RandomVec6(rng, 2.0).head<3>();
  Vec6 b = bias_hat + testing::RandomVec6(rng, 0.02);
  double delta = anchor;
  const double* params[] = {pi.data(), vi.data(), b.data(), pj.data(), vj.data(), &delta};
  Eigen::Matrix<double, 9, 1> r0, r1;
  Eigen::Matrix<double, 9, 7, Eigen::RowMajor> A0, A1, B0, B1;
  Eigen::Matrix<double, 9, 3, Eigen::RowMajor> V0, V1, W0, W1;
  Eigen::Matrix<double, 9, 6, Eigen::RowMajor> C0, C1;
  Eigen::Matrix<double, 9, 1> D;
  double* j0[] = {A0.data(), V0.data(), C0.data(), B0.data(), W0.data()};
  double* j1[] = {A1.data(), V1.data(), C1.data(), B1.data(), W1.data(), D.data()};
  ASSERT_TRUE(plain.Evaluate(params, r0.data(), j0));
  ASSERT_TRUE(shifted.Evaluate(params, r1.data(), j1));
  EXPECT_LT((r0 - r1).norm(), 1e-12 * (1.0 + r0.norm()));
  EXPECT_LT((A0 - A1).norm() + (B0 - B1).norm(), 1e-12 * (1.0 + A0.norm() + B0.norm()));
  EXPECT_LT((V0 - V1).norm() + (W0 - W1).norm() + (C0 - C1).norm(),
            1e-12 * (1.0 + V0.norm() + W0.norm() + C0.norm()));
  // δ is informed: a moving platform gives a non-zero column.
  EXPECT_GT(D.norm(), 1.0);
}

TEST(PreintegratedImuTimeOffsetFactor, JacobiansMatchNumeric) {
  std::mt19937 rng(17);
  PoseManifold pose_manifold;
  for (int trial = 0; trial < 6; ++trial) {
    // Random, near-π and near-identity states; biases away from b̄; δ away from δ̄ both ways.
    const double max_angle = trial < 2 ? 1.0 : (trial < 4 ? 3.1 : 1e-6);
    const Vec6 bias_hat = testing::RandomVec6(rng, 0.05);
    const PreintegratedImu pim = Preintegrate(0.3, 0.4, bias_hat, 5e-3);
    const double anchor = 0.02;
    const PreintegratedImuTimeOffsetFactor cost(pim, kGravity, Ends(0.3, 0.4, bias_hat), anchor);
    std::vector<double> pi = testing::PoseParameters(testing::RandomPose(rng, max_angle, 5.0));
    std::vector<double> pj = testing::PoseParameters(testing::RandomPose(rng, max_angle, 5.0));
    Vec3 vi = testing::RandomVec6(rng, 2.0).head<3>(), vj = testing::RandomVec6(rng, 2.0).head<3>();
    Vec6 b = bias_hat + testing::RandomVec6(rng, 0.05);
    double delta = anchor + (trial % 2 == 0 ? 0.015 : -0.008);
    EXPECT_TRUE(testing::JacobiansMatchNumeric(
        cost, {&pose_manifold, nullptr, nullptr, &pose_manifold, nullptr, nullptr},
        {pi.data(), vi.data(), b.data(), pj.data(), vj.data(), &delta}, 1e-5))
        << "trial " << trial;
  }
}

// The interval [a, b] preintegrated at δ̄; the truth at δ = δ̄ + d is the interval [a − d, b − d]
// re-integrated. The factor's residual of that truth is O(d²) (halving d quarters it), the plain
// factor's O(d).
TEST(PreintegratedImuTimeOffsetFactor, FirstOrderShiftMatchesTheReintegratedInterval) {
  std::mt19937 rng(23);
  const Vec6 bias_hat = testing::RandomVec6(rng, 0.05);
  const double a = 0.3, b = 0.4, anchor = 0.01;
  const PreintegratedImu pim = Preintegrate(a, b, bias_hat);
  const PreintegratedImuTimeOffsetFactor cost(pim, kGravity, Ends(a, b, bias_hat), anchor);
  const PreintegratedImuFactor plain(pim, kGravity);
  const SE3 Ti = testing::RandomPose(rng, 2.0, 3.0);
  const Vec3 vi(1.0, -0.5, 0.3);
  for (const double sign : {1.0, -1.0}) {
    double residual[2] = {0.0, 0.0};
    for (int half = 0; half < 2; ++half) {
      const double d = sign * (half == 0 ? 4e-3 : 2e-3);
      States s = Through(Preintegrate(a - d, b - d, bias_hat), Ti, vi);
      double delta = anchor + d;
      const double* params[] = {s.pi.data(), s.vi.data(), s.b.data(),
                                s.pj.data(), s.vj.data(), &delta};
      Eigen::Matrix<double, 9, 1> r, r_plain;
      ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
      ASSERT_TRUE(plain.Evaluate(params, r_plain.data(), nullptr));
      residual[half] = r.norm();
      EXPECT_LT(r.norm(), 0.05 * r_plain.norm()) << "d = " << d;
    }
    const double ratio = residual[0] / residual[1];
    EXPECT_GT(ratio, 3.2) << "sign " << sign;
    EXPECT_LT(ratio, 4.8) << "sign " << sign;
  }
}

TEST(PreintegratedImuTimeOffsetFactor, RejectsNonFiniteInput) {
  const Vec6 bias = Vec6::Zero();
  const PreintegratedImu pim = Preintegrate(0.0, 0.1, bias, 1e-3);
  PreintegrationEnds ends = Ends(0.0, 0.1, bias);
  EXPECT_THROW(PreintegratedImuTimeOffsetFactor(pim, kGravity, ends, std::nan("")),
               std::invalid_argument);
  ends.gyro_end.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(PreintegratedImuTimeOffsetFactor(pim, kGravity, ends, 0.0), std::invalid_argument);
  EXPECT_THROW(PreintegratedImuTimeOffsetFactor(PreintegratedImu(bias, Noise()), kGravity,
                                                Ends(0.0, 0.1, bias), 0.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::imu
