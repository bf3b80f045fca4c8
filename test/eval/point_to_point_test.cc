// The pieces shared by ctlio::eval's point-to-point registrations (point_to_point.h).
#include "ctlio/eval/point_to_point.h"

#include <gtest/gtest.h>

#include "ctlio/manifolds/so3.h"

namespace ctlio::eval {
namespace {

TEST(FirstPointPerVoxel, KeepsTheFirstPointOfEachVoxelInInputOrder) {
  const std::vector<Vec3> points = {Vec3(0.1, 0.1, 0.1), Vec3(0.4, 0.2, 0.3), Vec3(-0.1, 0, 0),
                                    Vec3(0.6, 0.1, 0.1), Vec3(0.2, 0.4, 0.1)};
  const std::vector<Vec3> kept = FirstPointPerVoxel(points, 0.5);
  ASSERT_EQ(kept.size(), 3u);  // voxels (0,0,0), (−1,0,0), (1,0,0)
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[2]);
  EXPECT_EQ(kept[2], points[3]);
  EXPECT_EQ(FirstPointPerVoxel(points, 0.0).size(), points.size());
}

TEST(PointToPointSystem, OneStepRecoversATranslationAndDownweightsAnOutlier) {
  // Residuals of points shifted by t: e = t + δ_t (rotation part unexercised by symmetry):
  // one Gauss–Newton step returns δ_t = −t when every weight is equal.
  const Vec3 t(0.02, -0.01, 0.03);
  const Vec3 corners[] = {Vec3(1, 0, 0),  Vec3(-1, 0, 0), Vec3(0, 1, 0),
                          Vec3(0, -1, 0), Vec3(0, 0, 1),  Vec3(0, 0, -1)};
  PointToPointSystem system;
  for (const Vec3& q : corners) {
    Eigen::Matrix<double, 3, 6> J;
    J << Mat3::Identity(), -so3::Hat(q);
    system.Add(t, J, 1.0);
  }
  EXPECT_EQ(system.used(), 6);
  EXPECT_LT((system.Step().head<3>() + t).norm(), 1e-12);
  EXPECT_LT(system.Step().tail<3>().norm(), 1e-12);
  // A 1 m outlier with κ = 0.01 m² has weight ≈ 1e-4 of an inlier's: the step barely moves.
  Eigen::Matrix<double, 3, 6> J;
  J << Mat3::Identity(), -so3::Hat(Vec3(2, 0, 0));
  PointToPointSystem robust = system;
  robust.Add(Vec3(1, 0, 0), J, 0.01);
  EXPECT_LT((robust.Step().head<3>() + t).norm(), 1e-3);
}

}  // namespace
}  // namespace ctlio::eval
