// The small point-to-point odometry (apps/eval point_odometry.h) follows a sensor moving at
// constant velocity through a structured room.
#include "ctlio/eval/point_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace ctlio::eval {
namespace {

// Sweeps of a room (floor, two walls, boxes) seen from a sensor moving with the body twist `xi`
// per sweep: each point is measured at its own time τ ∈ [−½, ½) sweep, from T(k + τ). From sweep
// `jump_at` on the sensor also slides by `jump` m per sweep along x and y (a prediction error).
// `sweeps` sweeps, the twist scaled by `speed`, `draws` × 4¼ points in the room.
std::vector<SE3> RunRoom(bool deskew, double* final_error, PointOdometryOptions options = {},
                         int jump_at = 1000, double jump = 0.0,
                         std::vector<double>* sigmas = nullptr, int sweeps = 12, double speed = 1.0,
                         int draws = 40000) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> world;
  for (int k = 0; k < draws; ++k) {
    const double a = 60 * u(rng) - 30, b = 40 * u(rng) - 20, h = 6 * u(rng);
    world.push_back(Vec3(a, b, -1.5));
    world.push_back(Vec3(25, b, h - 1.5));
    world.push_back(Vec3(a, 15, h - 1.5));
    world.push_back(Vec3(-25, b, h - 1.5));
    if (k % 4 == 0) world.push_back(Vec3(int(a / 6) * 6 + u(rng), int(b / 6) * 6, h - 1.5));
  }
  Vec6 xi;
  xi << 0.8, 0.05, 0.0, 0.0, 0.0, 0.08;  // per sweep: 8 m/s and 0.8 rad/s at 10 Hz
  xi *= speed;
  auto pose = [&](double s) {
    const double slide = s > jump_at ? jump * (s - jump_at) : 0.0;
    return SE3(Mat3::Identity(), Vec3(slide, slide, 0)) * SE3::Exp(s * xi);
  };
  options.deskew = deskew;
  PointOdometry odometry(pose(0), options, SE3::Exp(xi));  // started in motion
  for (int k = 0; k < sweeps; ++k) {
    std::vector<Vec3> points;
    std::vector<double> times;
    for (const Vec3& p : world) {
      const double tau = u(rng) - 0.5;
      const Vec3 q = pose(k + tau).Inverse() * p;
      if (q.norm() > 1.0 && q.norm() < 60.0) {
        points.push_back(q);
        times.push_back(0.1 * tau);
      }
    }
    odometry.Register(points, times, 0.1);
  }
  *final_error = (odometry.poses().back().translation() - pose(sweeps - 1).translation()).norm();
  if (sigmas != nullptr) *sigmas = odometry.sigmas();
  return odometry.poses();
}

TEST(AdaptiveThreshold, RootMeanSquareOfThePredictionErrorsAboveTheMinimumMotion) {
  AdaptiveThreshold t(2.0, 0.1, 100.0);
  EXPECT_EQ(t.Sigma(), 2.0);
  // Below the minimum motion: not counted, σ stays.
  EXPECT_NEAR(t.Update(SE3(Mat3::Identity(), Vec3(0.05, 0, 0))), 0.05, 1e-12);
  EXPECT_EQ(t.Sigma(), 2.0);
  EXPECT_EQ(t.samples(), 0);
  t.Update(SE3(Mat3::Identity(), Vec3(0, 0.3, 0)));
  EXPECT_NEAR(t.Sigma(), 0.3, 1e-12);
  // A rotation of θ moves a point at the largest range by 2·r_max·sin(θ/2).
  Vec6 rot;
  rot << 0, 0, 0, 0, 0, 0.01;
  const double d = 2.0 * 100.0 * std::sin(0.005);
  EXPECT_NEAR(t.Update(SE3::Exp(rot)), d, 1e-9);
  EXPECT_NEAR(t.Sigma(), std::sqrt((0.09 + d * d) / 2.0), 1e-9);
  EXPECT_EQ(t.samples(), 2);
}

TEST(PointOdometry, FollowsAConstantVelocityMotion) {
  double with = 0.0, without = 0.0;
  EXPECT_EQ(RunRoom(true, &with).size(), 12u);
  RunRoom(false, &without);
  EXPECT_LT(with, 0.03);  // of 9.6 m travelled
  // The skew of 0.8 m and 4.6° per sweep is symmetric about the sweep's middle, so the pose
  // comes out close without deskewing too, but not the same.
  EXPECT_LT(without, 0.1);
  EXPECT_GT(std::abs(without - with), 1e-4);
}

// A slide of 0.4 m per sweep along x and y from sweep 6 on: the constant-velocity prediction is
// 0.57 m off there, every wall farther than the gate. The adaptive threshold, still at its initial
// σ (the smooth sweeps before moved the prediction by less than min_motion), finds the
// correspondences and then learns σ of the order of the error; a fixed σ of 0.05 m (gate
// 0.15 m) keeps only the floor, which says nothing about x and y.
TEST(PointOdometry, AdaptiveThresholdFollowsASuddenChangeOfMotion) {
  double adaptive = 0.0, fixed = 0.0;
  std::vector<double> sigmas;
  RunRoom(true, &adaptive, {}, 6, 0.4, &sigmas);
  EXPECT_LT(adaptive, 0.05);
  ASSERT_EQ(sigmas.size(), 12u);
  EXPECT_EQ(sigmas[6], 2.0);
  EXPECT_GT(sigmas[8], 0.1);
  EXPECT_LT(sigmas[8], 1.0);
  PointOdometryOptions tight;
  tight.fixed_sigma = 0.05;
  RunRoom(true, &fixed, tight, 6, 0.4);
  EXPECT_GT(fixed, 0.2);
}

// The constant-velocity prediction composes T_{k−1}·(T_{k−2}⁻¹·T_{k−1}) every sweep, with the
// inverse as a transpose: without projecting the poses back onto SO(3) a rotation's deviation
// from orthogonality grows by 1 + √2 per sweep (rounding errors of 1e-16 are 1e-2 after 35
// sweeps), and the odometry left the track after 38–42 sweeps in every simulated world.
TEST(PointOdometry, PosesStayRotationsOverALongRun) {
  double error = 0.0;
  const std::vector<SE3> poses = RunRoom(true, &error, {}, 1000, 0.0, nullptr, 50, 0.2, 10000);
  ASSERT_EQ(poses.size(), 50u);
  for (const SE3& T : poses) {
    EXPECT_LT((T.rotation().transpose() * T.rotation() - Mat3::Identity()).norm(), 1e-12);
  }
  EXPECT_LT(error, 0.05);  // of 8 m travelled and 0.8 rad turned
}

TEST(PointOdometry, RejectsMismatchedInput) {
  PointOdometry odometry;
  EXPECT_THROW(odometry.Register({Vec3(1, 2, 3)}, {}, 0.1), std::invalid_argument);
  EXPECT_THROW(odometry.Register({Vec3(1, 2, 3)}, {0.0}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::eval
