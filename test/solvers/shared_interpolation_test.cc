// The window's evaluation callback (SharedInterpolationCallback, a ceres::EvaluationCallback):
// continuous-time point-to-plane residuals whose firings share one SharedPoseInterpolation, and
// the gyro and accelerometer residuals of an IMU sample sharing one gp::SharedStateInterpolation
// (all of them on one knot interval, whose local variables the callback forms once), must
// (a) read the prepared interpolation in every evaluation of Ceres' solve and of the window's
// own linearisation (marginalisation, covariance) — none interpolates on its own — and
// (b) give the same solution and the same marginal prior as the same residuals without sharing.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>
#include <vector>

#include "common/singer_model.h"
#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/priors/state_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio {
namespace {

constexpr double kT1 = 0.1;  // knot times 0 and kT1
constexpr int kFirings = 12, kPointsPerFiring = 8, kImuSamples = 10;

struct Scene {
  gp::KnotState truth0, truth1, guess0, guess1;
  std::vector<double> tau;                            // per firing
  std::vector<std::vector<PlaneAssociation>> planes;  // per firing
};

// Points seen from the true trajectory, each on a plane through its true map position.
Scene MakeScene(uint32_t seed, int firings = kFirings) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto vec6 = [&](double s) {
    Vec6 v;
    for (int i = 0; i < 6; ++i) v[i] = s * u(rng);
    return v;
  };
  Scene s;
  s.truth0.pose = SE3(so3::Exp(Vec3(0.3, -0.2, 2.5)), Vec3(1, 2, 3));
  s.truth0.velocity = vec6(1.0);
  s.truth0.acceleration = vec6(2.0);
  s.truth1.pose = SE3::Exp(kT1 * s.truth0.velocity) * s.truth0.pose;
  s.truth1.velocity = s.truth0.velocity + kT1 * s.truth0.acceleration;
  s.truth1.acceleration = s.truth0.acceleration;
  s.guess0 = s.truth0;
  s.guess1 = s.truth1;
  s.guess0.pose = SE3::Exp(vec6(0.02)) * s.truth0.pose;
  s.guess1.pose = SE3::Exp(vec6(0.05)) * s.truth1.pose;
  s.guess1.velocity += vec6(0.2);
  for (int f = 0; f < firings; ++f) {
    s.tau.push_back(kT1 * (f + 0.5) / firings);
    const gp::GpInterpolator interp(ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1,
                                    s.tau.back());
    SE3 T_rm;
    interp.Pose(s.truth0, s.truth1, &T_rm, nullptr, nullptr);
    s.planes.emplace_back();
    for (int i = 0; i < kPointsPerFiring; ++i) {
      PlaneAssociation a;
      a.point_robot = 10.0 * Vec3(u(rng), u(rng), u(rng));
      a.plane_normal = Vec3(u(rng), u(rng), u(rng)).normalized();
      a.plane_point = T_rm.Inverse() * a.point_robot + 0.5 * a.plane_normal.unitOrthogonal();
      a.weight = 1.0 / 0.05;
      s.planes.back().push_back(a);
    }
  }
  return s;
}

struct Built {
  std::unique_ptr<SlidingWindow> window;
  std::vector<std::shared_ptr<SharedPoseInterpolation>> firings;   // empty without sharing
  std::vector<std::shared_ptr<gp::SharedStateInterpolation>> imu;  // empty without sharing
};

Built Build(const Scene& s, bool shared, int threads = 1) {
  Built b;
  SlidingWindowOptions options;
  options.solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.solver.max_num_iterations = 20;
  options.solver.num_threads = threads;
  b.window = std::make_unique<SlidingWindow>(options);
  SlidingWindow& w = *b.window;
  const std::vector<StateId> ids = {0, 1, 2, 3, 4, 5};
  for (const auto& [first, x] : {std::make_pair(0, &s.guess0), std::make_pair(3, &s.guess1)}) {
    w.AddPoseState(first, x->pose);
    w.AddVectorState(first + 1, x->velocity);
    w.AddVectorState(first + 2, x->acceleration);
  }
  w.AddResidualBlock(
      StatePrior::FromCovariance(s.guess0.pose, s.guess0.velocity, s.guess0.acceleration,
                                 1e-2 * Eigen::Matrix<double, 18, 18>::Identity()),
      nullptr, {0, 1, 2});
  w.AddResidualBlock(new gp::SingerPrior(ctlio::testing::NewerCollegeSingerModel(), kT1), nullptr,
                     ids);
  const SharedPoseInterpolation::KnotBlocks blocks = {w.State(0), w.State(1), w.State(2),
                                                      w.State(3), w.State(4), w.State(5)};
  for (size_t f = 0; f < s.tau.size(); ++f) {
    auto interpolator = std::make_shared<const gp::GpInterpolator>(
        ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1, s.tau[f]);
    std::shared_ptr<SharedPoseInterpolation> firing;
    if (shared) {
      firing = std::make_shared<SharedPoseInterpolation>(interpolator, blocks);
      w.shared_interpolations().Add(firing);
      b.firings.push_back(firing);
    }
    for (const PlaneAssociation& a : s.planes[f]) {
      ceres::CostFunction* cost = shared ? new ContinuousPointToPlane(firing, a)
                                         : new ContinuousPointToPlane(interpolator, a);
      w.AddResidualBlock(cost, new ceres::CauchyLoss(1.0), ids);
    }
  }
  // IMU samples (gyro + accelerometer with the exact specific force and a Cauchy loss, as in the
  // LIO) read from the true trajectory; biases and gravity held.
  const Vec6 zero = Vec6::Zero();
  w.AddVectorState(6, zero);
  w.AddVectorState(7, zero);
  w.AddRotationState(8, Mat3::Identity());
  for (StateId id : {6, 7, 8}) w.SetStateConstant(id, true);
  std::vector<StateId> imu_ids = ids;
  imu_ids.push_back(6);
  imu_ids.push_back(7);
  for (int i = 0; i < kImuSamples; ++i) {
    const double tau = kT1 * (i + 0.3) / kImuSamples;
    gp::KnotState x;
    gp::GpInterpolator(ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1, tau)
        .State(s.truth0, s.truth1, &x, nullptr, nullptr);
    const Vec3 gyro = -x.velocity.tail<3>();
    const Vec3 accel = -x.acceleration.head<3>() +
                       x.velocity.tail<3>().cross(x.velocity.head<3>()) -
                       x.pose.rotation() * Vec3(0, 0, -9.81);
    const Mat3 cov = 1e-4 * Mat3::Identity();
    const auto exact = imu::AccelModel::kSpecificForce;
    ceres::CostFunction *g = nullptr, *a = nullptr;
    if (shared) {
      const auto state = std::make_shared<gp::SharedStateInterpolation>(
          ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1, tau, blocks);
      w.shared_interpolations().Add(state);
      b.imu.push_back(state);
      g = new imu::ImuGyroMeasurement(state, gyro, cov);
      a = new imu::ImuAccelMeasurement(state, accel, cov, 9.81, exact);
    } else {
      g = new imu::ImuGyroMeasurement(ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1, tau,
                                      gyro, cov);
      a = new imu::ImuAccelMeasurement(ctlio::testing::NewerCollegeSingerModel(), 0.0, kT1, tau,
                                       accel, cov, 9.81, exact);
    }
    w.AddResidualBlock(g, nullptr, imu_ids);
    std::vector<StateId> accel_ids = imu_ids;
    accel_ids.push_back(8);
    w.AddResidualBlock(a, new ceres::CauchyLoss(1.0), accel_ids);
  }
  return b;
}

int64_t Computed(const Built& b) {
  int64_t n = 0;
  for (const auto& f : b.firings) n += f->num_computed();
  for (const auto& f : b.imu) n += f->num_computed();
  return n;
}

TEST(SharedInterpolationCallback, SolveReadsPreparedInterpolationAndMatchesUnshared) {
  const Scene scene = MakeScene(3);
  Built shared = Build(scene, true), plain = Build(scene, false);
  EXPECT_EQ(shared.window->shared_interpolations().size(),
            static_cast<size_t>(kFirings + kImuSamples));
  const ceres::Solver::Summary a = shared.window->Solve();
  const ceres::Solver::Summary b = plain.window->Solve();
  EXPECT_GT(a.iterations.size(), 2u);
  EXPECT_EQ(Computed(shared), 0) << "an evaluation inside the solve interpolated on its own";
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-9 * b.final_cost);
  EXPECT_LT(a.final_cost, a.initial_cost);
  for (StateId id = 0; id < 6; ++id) {
    EXPECT_LT((shared.window->Vector(id) - plain.window->Vector(id)).cwiseAbs().maxCoeff(), 1e-9)
        << "state " << id;
  }
}

// With the solver's threads the callback prepares the interpolations in parallel chunks once
// there are enough of them (here 400 firings): every one is still prepared (none of the 4,000
// residuals interpolates on its own) and the solution is that of one thread (up to the order of
// Ceres' own parallel sums).
TEST(SharedInterpolationCallback, ThreadsPrepareEveryInterpolation) {
  const Scene scene = MakeScene(5, 400);
  Built one = Build(scene, true, 1), two = Build(scene, true, 2);
  const ceres::Solver::Summary a = one.window->Solve();
  const ceres::Solver::Summary b = two.window->Solve();
  EXPECT_GT(b.iterations.size(), 2u);
  EXPECT_EQ(Computed(two), 0) << "a residual read an interpolation the callback skipped";
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-9 * a.final_cost);
  for (StateId id = 0; id < 6; ++id) {
    EXPECT_LT((one.window->Vector(id) - two.window->Vector(id)).cwiseAbs().maxCoeff(), 1e-9)
        << "state " << id;
  }
}

TEST(SharedInterpolationCallback, MarginalizationPreparesBeforeLinearising) {
  const Scene scene = MakeScene(4);
  Built shared = Build(scene, true), plain = Build(scene, false);
  shared.window->Solve();
  plain.window->Solve();
  // Move the estimate after the solve, as a caller may: the last prepared point is stale.
  for (Built* b : {&shared, &plain}) b->window->State(4)[0] += 0.01;
  Eigen::MatrixXd H[2];
  Eigen::VectorXd g[2];
  int c = 0;
  for (Built* b : {&shared, &plain}) {
    std::vector<ceres::ResidualBlockId> all;
    for (StateId id = 0; id < 6; ++id) {
      for (ceres::ResidualBlockId r : b->window->ResidualBlocksOf(id)) all.push_back(r);
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    b->window->Linearize(all, {0, 1, 2, 3, 4, 5}, &H[c], &g[c]);
    ++c;
  }
  EXPECT_EQ(Computed(shared), 0) << "the linearisation interpolated per point";
  EXPECT_LT((H[0] - H[1]).cwiseAbs().maxCoeff(), 1e-9 * H[1].cwiseAbs().maxCoeff());
  EXPECT_LT((g[0] - g[1]).cwiseAbs().maxCoeff(), 1e-9 * g[1].cwiseAbs().maxCoeff() + 1e-12);
  // Marginalising knot 0 removes its residuals: every firing expires from the callback.
  const MarginalizationReport report = shared.window->Marginalize({0, 1, 2});
  EXPECT_GT(report.prior_rank, 0);
  EXPECT_EQ(Computed(shared), 0);
  shared.firings.clear();
  shared.imu.clear();
  EXPECT_EQ(shared.window->shared_interpolations().size(), 0u);
}

}  // namespace
}  // namespace ctlio
