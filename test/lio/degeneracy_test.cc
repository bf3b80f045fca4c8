// Degeneracy of the lidar term (solvers/lio/degeneracy.h) on synthetic scenes: a corridor (walls
// and floor/ceiling along one axis only) leaves exactly that axis unconstrained, in the body
// frame, for both pose parametrisations (the baseline's T_wb, the GP knots' T_rm); a closed room
// leaves none; the rest of the window's information is the marginal of the other factors; the
// remapping prior acts only along the degenerate directions.
#include "ctlio/solvers/lio/degeneracy.h"

#include <gtest/gtest.h>

#include <random>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/factors/lidar/point_to_plane_world.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {
namespace {

constexpr StateId kPose = 1;

// A scene of planes (point on the plane, normal) sampled at random points around the origin.
struct Plane {
  Vec3 point, normal;
};

// The corridor: walls y = ±1.5, floor z = 0, ceiling z = 3, running along the world x axis.
std::vector<Plane> Corridor() {
  return {{Vec3(0, 1.5, 0), Vec3(0, -1, 0)},
          {Vec3(0, -1.5, 0), Vec3(0, 1, 0)},
          {Vec3(0, 0, 0), Vec3(0, 0, 1)},
          {Vec3(0, 0, 3), Vec3(0, 0, -1)}};
}

std::vector<Plane> Room() {
  std::vector<Plane> planes = Corridor();
  planes.push_back({Vec3(20, 0, 0), Vec3(-1, 0, 0)});
  planes.push_back({Vec3(-20, 0, 0), Vec3(1, 0, 0)});
  return planes;
}

// Points on the planes (within |x| < 20 m), associated with their plane, as seen from T_wb.
std::vector<PlaneAssociation> Scan(const std::vector<Plane>& planes, const SE3& T_wb, int n,
                                   uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<PlaneAssociation> out;
  for (int i = 0; i < n; ++i) {
    const Plane& pl = planes[i % planes.size()];
    // A random point of the plane: move within it (remove the normal component).
    Vec3 d(20 * u(rng), 1.5 * u(rng), 1.5 + 1.5 * u(rng));
    d -= pl.normal * pl.normal.dot(d - pl.point);
    PlaneAssociation a;
    a.plane_point = d;
    a.plane_normal = pl.normal;
    a.point_robot = T_wb.Inverse() * d;
    a.weight = 1.0 / 0.05;
    out.push_back(a);
  }
  return out;
}

SE3 BodyPose() {
  // Yawed 30° and pitched 5°: the body axes differ from the corridor's.
  const Mat3 C =
      (Eigen::AngleAxisd(0.5236, Vec3::UnitZ()) * Eigen::AngleAxisd(0.0873, Vec3::UnitY()))
          .toRotationMatrix();
  return SE3(C, Vec3(3.0, 0.2, 1.4));
}

struct Built {
  std::unique_ptr<SlidingWindow> window;
  std::vector<ceres::ResidualBlockId> lidar;
  Mat6 A;
};

// `world_pose`: the state is T_wb (PointToPlaneWorld); else T_rm = T_wb⁻¹ (PointToPlane).
Built Build(const std::vector<Plane>& planes, bool world_pose) {
  Built b;
  b.window = std::make_unique<SlidingWindow>();
  const SE3 T_wb = BodyPose();
  b.window->AddPoseState(kPose, world_pose ? T_wb : T_wb.Inverse());
  for (const PlaneAssociation& a : Scan(planes, T_wb, 400, 7)) {
    ceres::CostFunction* f = world_pose
                                 ? static_cast<ceres::CostFunction*>(new PointToPlaneWorld(a))
                                 : static_cast<ceres::CostFunction*>(new PointToPlane(a));
    b.lidar.push_back(b.window->AddResidualBlock(f, nullptr, {kPose}));
  }
  b.A = world_pose ? T_wb.Adjoint() : Mat6(-Mat6::Identity());
  return b;
}

TEST(Degeneracy, CorridorAxisIsTheOneDegenerateDirectionInTheBodyFrame) {
  const Vec3 axis_body = BodyPose().rotation().transpose() * Vec3::UnitX();
  for (const bool world_pose : {true, false}) {
    const Built b = Build(Corridor(), world_pose);
    const Mat6 H = PoseInformation(*b.window, b.lidar, kPose, b.A);
    const DegeneracyReport r = AnalyseDegeneracy(H, DegeneracyOptions());
    ASSERT_TRUE(r.analysed);
    ASSERT_EQ(r.num_degenerate(), 1) << "world_pose " << world_pose << "\nH =\n" << H;
    const Vec6& u = r.directions[0];
    EXPECT_LT(u.tail<3>().norm(), 1e-9);  // a translation
    EXPECT_GT(std::abs(u.head<3>().dot(axis_body)), 1.0 - 1e-9) << u.transpose();
    EXPECT_LT(r.translation_eigenvalues[0], 1e-9);
    EXPECT_GT(r.translation_eigenvalues[1], 0.5);
    EXPECT_GT(r.rotation_eigenvalues[0], DegeneracyOptions().rotation_threshold);
    EXPECT_LT(r.lidar_information, 1e-6);
    EXPECT_EQ(r.DirectionString().substr(0, 2), "t:");
  }
}

TEST(Degeneracy, ClosedRoomHasNoDegenerateDirection) {
  for (const bool world_pose : {true, false}) {
    const Built b = Build(Room(), world_pose);
    const DegeneracyReport r =
        AnalyseDegeneracy(PoseInformation(*b.window, b.lidar, kPose, b.A), DegeneracyOptions());
    EXPECT_EQ(r.num_degenerate(), 0)
        << r.translation_eigenvalues.transpose() << " | " << r.rotation_eigenvalues.transpose();
    EXPECT_EQ(r.DirectionString(), "-");
  }
}

TEST(Degeneracy, ThresholdDecides) {
  const Built b = Build(Room(), true);
  const Mat6 H = PoseInformation(*b.window, b.lidar, kPose, b.A);
  DegeneracyOptions o;
  o.translation_threshold = 0.0;
  o.rotation_threshold = 0.0;
  EXPECT_EQ(AnalyseDegeneracy(H, o).num_degenerate(), 0);
  o.translation_threshold = 2.9;  // above every normalised eigenvalue but the largest
  EXPECT_GE(AnalyseDegeneracy(H, o).num_degenerate(), 2);
  o.translation_threshold = 3.0;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

TEST(Degeneracy, PriorInformationIsTheMarginalOfTheOtherFactors) {
  Built b = Build(Corridor(), true);
  // A pose prior with σ = 0.1 m along every world axis and 0.01 rad: its information along the
  // corridor axis (body frame) is 100, whatever the lidar.
  Mat6 cov = Mat6::Zero();
  cov.diagonal() << 0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4;
  b.window->AddResidualBlock(PosePrior::FromCovariance(BodyPose(), cov), nullptr, {kPose});
  const Mat6 P = OtherInformation(*b.window, b.lidar, kPose, b.A);
  const Vec3 axis_body = BodyPose().rotation().transpose() * Vec3::UnitX();
  Vec6 u = Vec6::Zero();
  u.head<3>() = axis_body;
  // Ad(T_wb) mixes the body rotation into the world translation (p^C): along a pure body
  // translation the prior's information is exactly that of a world translation C·u.
  EXPECT_NEAR(u.dot(P * u), 100.0, 1e-6);
}

TEST(Degeneracy, RemapPriorActsOnlyAlongTheDegenerateDirections) {
  const Built b = Build(Corridor(), false);
  const DegeneracyOptions o;
  const DegeneracyReport r = AnalyseDegeneracy(PoseInformation(*b.window, b.lidar, kPose, b.A), o);
  ASSERT_EQ(r.num_degenerate(), 1);
  const Mat6 W = RemapSqrtInformation(r, o, b.A);
  const Vec6& u = r.directions[0];
  // Along u (state tangent −u for T_rm): √w; orthogonal to it: nothing.
  EXPECT_NEAR((W * (b.A * u)).norm(), std::sqrt(o.remap_information), 1e-6);
  for (int i = 0; i < 6; ++i) {
    Vec6 v = Vec6::Unit(i);
    v -= u * u.dot(v);
    EXPECT_LT((W * (b.A * v)).norm(), 1e-6 * std::sqrt(o.remap_information));
  }
}

}  // namespace
}  // namespace ctlio::lio
