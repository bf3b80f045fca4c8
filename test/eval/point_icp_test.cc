// The small point-to-point ICP (apps/eval point_icp.h) recovers a known motion of a structured
// cloud.
#include "ctlio/eval/point_icp.h"

#include <gtest/gtest.h>

#include <random>

namespace ctlio::eval {
namespace {

TEST(PointIcp, RecoversAKnownMotionOfARoomCorner) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 0.005);
  std::vector<Vec3> target;
  for (int k = 0; k < 30000; ++k) {
    const double a = 20 * u(rng) - 10, b = 20 * u(rng) - 10, h = 4 * u(rng);
    target.push_back(Vec3(a, b, -1.5 + n(rng)));                                // floor
    target.push_back(Vec3(8 + n(rng), b, h - 1.5));                             // wall
    target.push_back(Vec3(a, 6 + n(rng), h - 1.5));                             // wall
    if (k % 10 == 0) target.push_back(Vec3(-3 + u(rng), -4 + u(rng), u(rng)));  // clutter
  }
  Vec6 xi;
  xi << 0.4, -0.3, 0.05, 0.01, -0.02, 0.08;
  const SE3 truth = SE3::Exp(xi);  // T_target_source
  std::vector<Vec3> source;
  for (const Vec3& p : target) source.push_back(truth.Inverse() * p);
  const PointIcpResult r = RegisterPointToPoint(source, target, SE3());
  const SE3 error = truth.Inverse() * r.target_from_source;
  EXPECT_LT(error.translation().norm(), 0.01);
  EXPECT_LT(error.Log().tail<3>().norm(), 0.002);
  EXPECT_GT(r.correspondences, 1000);
}

}  // namespace
}  // namespace ctlio::eval
