// Trajectory evaluation (SPEC §6 metric): Umeyama recovers a known SE(3)/Sim(3) exactly; ATE of a
// trajectory against itself under a random rigid transform is 0; known perturbations give the
// hand-computed ATE and RPE; association within a tolerance.
#include "ctlio/eval/trajectory_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

namespace ctlio::eval {
namespace {

using io::StampedPose;

std::vector<StampedPose> Wiggly(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<StampedPose> out;
  for (size_t i = 0; i < n; ++i) {
    const double t = 0.1 * double(i);
    out.push_back({int64_t(i) * 100'000'000,
                   SE3(so3::Exp(Vec3(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 0.5 * t)),
                       Vec3(5 * std::cos(0.3 * t) + 0.01 * g(rng), 3 * std::sin(0.4 * t),
                            0.5 * std::sin(t)))});
  }
  return out;
}

SE3 RandomSE3(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return SE3(so3::Exp(Vec3(g(rng), g(rng), g(rng))), Vec3(10 * g(rng), 10 * g(rng), 10 * g(rng)));
}

TEST(Umeyama, RecoversKnownSe3AndSim3Exactly) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3> src, dst_rigid, dst_sim;
    const SE3 T = RandomSE3(rng);
    const double s = 0.3 + 3.0 * std::abs(g(rng));
    for (int i = 0; i < 30; ++i) {
      const Vec3 p(5 * g(rng), 5 * g(rng), 5 * g(rng));
      src.push_back(p);
      dst_rigid.push_back(T * p);
      dst_sim.push_back(s * (T.rotation() * p) + T.translation());
    }
    const Similarity a = Umeyama(src, dst_rigid, false);
    EXPECT_LT((a.pose.Inverse() * T).Log().norm(), 1e-10);
    EXPECT_EQ(a.scale, 1.0);
    const Similarity b = Umeyama(src, dst_sim, true);
    EXPECT_NEAR(b.scale, s, 1e-10 * s);
    EXPECT_LT((b.pose.Inverse() * T).Log().norm(), 1e-10);
  }
  // Degenerate input is an error, not garbage.
  EXPECT_THROW(Umeyama({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)},
                       {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}, false),
               std::runtime_error);
  EXPECT_THROW(Umeyama({Vec3(0, 0, 0)}, {Vec3(0, 0, 0)}, false), std::runtime_error);
}

TEST(Ate, TrajectoryAgainstItselfUnderARandomRigidTransformIsZero) {
  std::mt19937 rng(11);
  const auto ref = Wiggly(200, 5);
  for (int trial = 0; trial < 5; ++trial) {
    const SE3 T = RandomSE3(rng);
    auto est = ref;
    for (auto& p : est) p.pose = T * p.pose;
    const AteResult se3 = ComputeAte(est, ref, AlignmentMode::kSe3);
    EXPECT_LT(se3.translation.rmse, 1e-9);
    EXPECT_LT(se3.translation.max, 1e-9);
    // Without alignment the same trajectory is far off.
    EXPECT_GT(ComputeAte(est, ref, AlignmentMode::kNone).translation.rmse, 0.1);
    // RPE is invariant to the world frame.
    EXPECT_LT(ComputeRpeTime(est, ref, 1.0).translation.rmse, 1e-9);
    EXPECT_LT(ComputeRpeDistance(est, ref, 2.0).rotation.rmse, 1e-6);
  }
  // A scaled copy: zero under Sim(3), not under SE(3).
  auto scaled = ref;
  for (auto& p : scaled) p.pose = SE3(p.pose.rotation(), 1.7 * p.pose.translation());
  const AteResult sim3 = ComputeAte(scaled, ref, AlignmentMode::kSim3);
  EXPECT_LT(sim3.translation.rmse, 1e-9);
  EXPECT_NEAR(sim3.alignment.scale, 1 / 1.7, 1e-12);
  EXPECT_GT(ComputeAte(scaled, ref, AlignmentMode::kSe3).translation.rmse, 0.5);
}

TEST(Ate, KnownPerturbationGivesTheHandComputedRmse) {
  // Reference positions on a symmetric 4×4 grid in the plane z = 0 (times 0..15 s). The estimate
  // adds δz = a·sign(x)·sign(y): a "saddle" orthogonal to 1, x and y over the grid, so the
  // cross-covariance equals the grid's own covariance and the optimal alignment is the identity.
  // Every error is then |δz| = a, so ATE RMSE = a = 0.1 m exactly.
  std::vector<StampedPose> ref, est;
  const double a = 0.1;
  int k = 0;
  for (double x : {-2.0, -1.0, 1.0, 2.0}) {
    for (double y : {-2.0, -1.0, 1.0, 2.0}) {
      const int64_t t = int64_t(k++) * 1'000'000'000;
      ref.push_back({t, SE3(Mat3::Identity(), Vec3(x, y, 0))});
      est.push_back(
          {t, SE3(Mat3::Identity(), Vec3(x, y, a * (x > 0 ? 1 : -1) * (y > 0 ? 1 : -1)))});
    }
  }
  const AteResult r = ComputeAte(est, ref, AlignmentMode::kSe3);
  EXPECT_NEAR(r.translation.rmse, a, 1e-12);
  EXPECT_NEAR(r.translation.max, a, 1e-12);
  EXPECT_LT(r.alignment.pose.Log().norm(), 1e-12);

  // A second hand computation: constant offset (0.3, 0.4, 0) on half the poses, none on the
  // other half, without alignment: errors 0.5 and 0 → RMSE = 0.5/√2.
  auto shifted = ref;
  for (size_t i = 0; i < shifted.size(); i += 2) {
    shifted[i].pose = SE3(Mat3::Identity(), shifted[i].pose.translation() + Vec3(0.3, 0.4, 0));
  }
  EXPECT_NEAR(ComputeAte(shifted, ref, AlignmentMode::kNone).translation.rmse, 0.5 / std::sqrt(2.0),
              1e-12);
}

TEST(Rpe, StraightLineWithScaleErrorGivesHandComputedValues) {
  // Reference moves 1 m/s along x (pose every 1 s), the estimate 1.1 m/s: over any 1 s or 1 m
  // window the relative translation is off by 0.1 m (10 %), rotation error 0.
  std::vector<StampedPose> ref, est;
  for (int i = 0; i < 21; ++i) {
    ref.push_back({int64_t(i) * 1'000'000'000, SE3(Mat3::Identity(), Vec3(i, 0, 0))});
    est.push_back({int64_t(i) * 1'000'000'000, SE3(Mat3::Identity(), Vec3(1.1 * i, 0, 0))});
  }
  const RpeResult t = ComputeRpeTime(est, ref, 1.0);
  EXPECT_EQ(t.translation.count, 20u);
  EXPECT_NEAR(t.translation.rmse, 0.1, 1e-12);
  EXPECT_NEAR(t.rotation.rmse, 0.0, 1e-12);
  const RpeResult d = ComputeRpeDistance(est, ref, 5.0);
  EXPECT_EQ(d.translation.count, 16u);
  EXPECT_NEAR(d.translation.rmse, 0.5, 1e-12);
  EXPECT_NEAR(d.translation_percent, 10.0, 1e-9);
  // A yaw error of 0.01 rad per step shows up in rotation RPE as 0.01 rad = 0.573 deg per 1 s.
  auto yaw = ref;
  for (int i = 0; i < 21; ++i) yaw[i].pose = SE3(so3::Exp(Vec3(0, 0, 0.01 * i)), Vec3(i, 0, 0));
  EXPECT_NEAR(ComputeRpeTime(yaw, ref, 1.0).rotation.rmse, 0.01 * 180 / M_PI, 1e-9);
}

TEST(Associate, NearestWithinToleranceOneToOne) {
  std::vector<StampedPose> ref, est;
  for (int i = 0; i < 10; ++i) ref.push_back({int64_t(i) * 100'000'000, SE3()});
  // Jitter of 3 ms, one estimate far off (55 ms), two estimates near the same reference.
  for (int64_t t : {3'000'000LL, 98'000'000LL, 255'000'000LL, 301'000'000LL, 399'000'000LL,
                    402'000'000LL, 500'000'000LL}) {
    est.push_back({t, SE3()});
  }
  const auto pairs = Associate(est, ref, 10'000'000);
  std::vector<std::pair<size_t, size_t>> expect = {{0, 0}, {1, 1}, {3, 3}, {4, 4}, {6, 5}};
  EXPECT_EQ(pairs, expect);
  EXPECT_TRUE(Associate(est, {}, 10'000'000).empty());
}

TEST(Report, TextAndJsonCarryTheNumbers) {
  const auto ref = Wiggly(50, 1);
  Report r;
  r.alignment = "se3";
  r.ate = ComputeAte(ref, ref, AlignmentMode::kSe3);
  r.rpe.push_back(ComputeRpeDistance(ref, ref, 1.0));
  r.rpe.push_back(ComputeRpeTime(ref, ref, 1.0));
  EXPECT_THAT(ReportText(r), ::testing::HasSubstr("ATE [m]   rmse 0.000000"));
  const std::string json = ReportJson(r);
  EXPECT_THAT(json, ::testing::HasSubstr("\"ate_m\": {\"count\": 50"));
  EXPECT_THAT(json, ::testing::HasSubstr("\"window\": \"1 m\""));
}

}  // namespace
}  // namespace ctlio::eval
