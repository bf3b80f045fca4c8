// The gyro and accelerometer factors of one IMU sample reading one gp::SharedStateInterpolation
// (the sample's state at τ formed once per evaluation, with the knot interval's local variables
// formed once for all samples, gp/shared_knot_interval.h): prepared, they give exactly the
// results of the factors that interpolate on their own, read nothing twice, and their Jacobians
// match numeric differentiation — at random, |φ| near π and near-identity knots, α·Δt → 0, and
// a rotated IMU on a non-zero lever arm.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/gp/shared_knot_interval.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "imu/imu_test_blocks.h"

namespace ctlio::imu {
namespace {

using ::ctlio::testing::Blocks;

// α·Δt → 0 on every axis (Δt = 0.1 s): the Singer functions' series branch near x = 0.
gp::SingerModel<6> NearWnoj() {
  Vec6 qc, alpha;
  qc << 5000, 5000, 5000, 500, 500, 500;
  alpha << 1e-7, 1e-7, 1e-7, 1e-5, 1e-5, 1e-5;
  return gp::SingerModel<6>(qc, alpha);
}

gp::KnotBlocks KnotsOf(const Blocks& b) {
  return {b.pose_k, b.vel_k, b.acc_k, b.pose_k1, b.vel_k1, b.acc_k1};
}

// Residual and every Jacobian block of `cost` at `params`.
struct Evaluation {
  std::vector<double> residual;
  std::vector<std::vector<double>> jacobians;
};
Evaluation EvaluateAll(const ceres::CostFunction& cost, const std::vector<const double*>& params) {
  Evaluation e;
  e.residual.resize(cost.num_residuals());
  std::vector<double*> jac;
  for (const int size : cost.parameter_block_sizes()) {
    e.jacobians.emplace_back(cost.num_residuals() * size);
  }
  for (auto& j : e.jacobians) jac.push_back(j.data());
  EXPECT_TRUE(cost.Evaluate(params.data(), e.residual.data(), jac.data()));
  return e;
}

// max over the residual and the Jacobian blocks of |a − b| / max(1, max|b|) (per block).
double Difference(const Evaluation& a, const Evaluation& b) {
  const auto diff = [](const std::vector<double>& x, const std::vector<double>& y) {
    double d = 0.0, scale = 1.0;
    for (size_t i = 0; i < x.size(); ++i) {
      d = std::max(d, std::abs(x[i] - y[i]));
      scale = std::max(scale, std::abs(y[i]));
    }
    return d / scale;
  };
  double d = diff(a.residual, b.residual);
  for (size_t j = 0; j < a.jacobians.size(); ++j)
    d = std::max(d, diff(a.jacobians[j], b.jacobians[j]));
  return d;
}

TEST(ImuSharedState, PreparedSharedStateGivesTheFactorsOwnResultsAndMatchesNumeric) {
  std::mt19937 rng(31);
  const testing::ImuManifolds manifolds;
  const Mat3 A = Mat3::Random();
  const Mat3 cov = 1e-3 * (A * A.transpose() + Mat3::Identity());
  for (int trial = 0; trial < 6; ++trial) {
    const Blocks blocks = testing::JacobianCheckBlocks(rng, trial);
    const ImuMounting mounting = ImuMounting::FromPose(testing::RandomPose(rng, 3.0, 0.5));
    ASSERT_GT(mounting.lever_arm.norm(), 0.01);
    const double t_k = 0.3, t_k1 = 0.4, tau = 0.3 + 0.1 * (trial + 0.5) / 6.0;
    const Vec3 gyro_meas = testing::RandomVec6(rng, 5.0).head<3>();
    const Vec3 accel_meas = testing::RandomVec6(rng, 5.0).head<3>();
    for (const gp::SingerModel<6>& model : {testing::Wnoj(), testing::Singer(), NearWnoj()}) {
      for (const AccelModel m : {AccelModel::kBodyCentric, AccelModel::kSpecificForce}) {
        for (const ImuMounting& mount : {ImuMounting(), mounting}) {
          const auto state = std::make_shared<gp::SharedStateInterpolation>(model, t_k, t_k1, tau,
                                                                            KnotsOf(blocks));
          state->set_interval(std::make_shared<gp::SharedKnotInterval>(KnotsOf(blocks)));
          const ImuGyroMeasurement gyro(state, gyro_meas, cov, mount);
          const ImuAccelMeasurement accel(state, accel_meas, cov, 9.81, m, mount);
          const ImuGyroMeasurement own_gyro(model, t_k, t_k1, tau, gyro_meas, cov, mount);
          const ImuAccelMeasurement own_accel(model, t_k, t_k1, tau, accel_meas, cov, 9.81, m,
                                              mount);
          state->Prepare();
          const Evaluation g = EvaluateAll(gyro, blocks.Gyro());
          const Evaluation a = EvaluateAll(accel, blocks.Accel());
          EXPECT_EQ(state->num_computed(), 0) << "the prepared state was not read";
          const Evaluation og = EvaluateAll(own_gyro, blocks.Gyro());
          const Evaluation oa = EvaluateAll(own_accel, blocks.Accel());
          // The shared state forms the union of both factors' rows (the accelerometer's reach the
          // ϖ̇ layer), which changes the gyro rows' Jacobians by rounding only; the
          // accelerometer's rows are the ones it forms alone.
          EXPECT_LT(Difference(g, og), 1e-13) << "gyro trial " << trial;
          EXPECT_TRUE(a.residual == oa.residual && a.jacobians == oa.jacobians)
              << "accel trial " << trial << " model " << static_cast<int>(m);
          // Numeric differentiation perturbs the knots: those evaluations interpolate on their
          // own, the unperturbed one reads the prepared state.
          if (m == AccelModel::kBodyCentric) {
            EXPECT_TRUE(testing::JacobiansMatchNumeric(gyro, manifolds.gyro, blocks.Gyro(), 1e-6))
                << "gyro trial " << trial;
          }
          EXPECT_TRUE(testing::JacobiansMatchNumeric(accel, manifolds.accel, blocks.Accel(), 1e-6))
              << "accel trial " << trial << " model " << static_cast<int>(m);
        }
      }
    }
  }
}

// A preparation forms the union of the rows its readers asked for; a reader that asks for more
// (added after the preparation) gets them computed, never stale rows.
TEST(ImuSharedState, RowsAddedAfterPreparingAreNotReadStale) {
  std::mt19937 rng(37);
  const Blocks blocks = testing::JacobianCheckBlocks(rng, 0);
  const auto state = std::make_shared<gp::SharedStateInterpolation>(testing::Singer(), 0.3, 0.4,
                                                                    0.33, KnotsOf(blocks));
  const ImuGyroMeasurement gyro(state, Vec3(0.1, 0.2, 0.3), 1e-3 * Mat3::Identity());
  state->Prepare();
  EXPECT_TRUE(state->prepared());
  const ImuAccelMeasurement accel(state, Vec3(0.1, 0.2, 9.8), 1e-3 * Mat3::Identity(), 9.81,
                                  AccelModel::kSpecificForce);
  EXPECT_FALSE(state->prepared());
  const ImuAccelMeasurement own(testing::Singer(), 0.3, 0.4, 0.33, Vec3(0.1, 0.2, 9.8),
                                1e-3 * Mat3::Identity(), 9.81, AccelModel::kSpecificForce);
  const Evaluation a = EvaluateAll(accel, blocks.Accel());
  const Evaluation o = EvaluateAll(own, blocks.Accel());
  EXPECT_TRUE(a.residual == o.residual && a.jacobians == o.jacobians);
  EXPECT_EQ(state->num_computed(), 1);
}

}  // namespace
}  // namespace ctlio::imu
