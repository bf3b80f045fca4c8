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
// per sweep: each point is measured at its own time τ ∈ [−½, ½) sweep, from T(k + τ).
std::vector<SE3> RunRoom(bool deskew, double* final_error) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> world;
  for (int k = 0; k < 40000; ++k) {
    const double a = 60 * u(rng) - 30, b = 40 * u(rng) - 20, h = 6 * u(rng);
    world.push_back(Vec3(a, b, -1.5));
    world.push_back(Vec3(25, b, h - 1.5));
    world.push_back(Vec3(a, 15, h - 1.5));
    world.push_back(Vec3(-25, b, h - 1.5));
    if (k % 4 == 0) world.push_back(Vec3(int(a / 6) * 6 + u(rng), int(b / 6) * 6, h - 1.5));
  }
  Vec6 xi;
  xi << 0.8, 0.05, 0.0, 0.0, 0.0, 0.08;  // per sweep: 8 m/s and 0.8 rad/s at 10 Hz
  auto pose = [&](double s) { return SE3::Exp(s * xi); };
  PointOdometryOptions options;
  options.deskew = deskew;
  PointOdometry odometry(pose(0), options);
  for (int k = 0; k < 12; ++k) {
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
  *final_error = (odometry.poses().back().translation() - pose(11).translation()).norm();
  return odometry.poses();
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

TEST(PointOdometry, RejectsMismatchedInput) {
  PointOdometry odometry;
  EXPECT_THROW(odometry.Register({Vec3(1, 2, 3)}, {}, 0.1), std::invalid_argument);
  EXPECT_THROW(odometry.Register({Vec3(1, 2, 3)}, {0.0}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::eval
