// The users' pose covariance outputs (apps/lio/covariance_output.h): trajectory_covariance.csv's
// order (t + the upper triangle row by row) on known values, and the ROS mapping of Σ of the left
// perturbation [ρ; φ] to nav_msgs/Odometry's [x y z roll pitch yaw] about fixed axes.
#include "lio/covariance_output.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "common/temp_dir.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::lioapp {
namespace {

TEST(CovarianceOutput, CsvHoldsTimeAndUpperTriangleRowByRow) {
  Mat6 S;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) S(i, j) = 10 * std::min(i, j) + std::max(i, j);  // symmetric
  std::vector<lio::ScanResult> scans(3);
  scans[0].t_ns = 100'000'000;  // the initialising scan: no covariance, no line
  scans[1].t_ns = 200'000'000;
  scans[1].has_pose_covariance = true;
  scans[1].pose_covariance = S;
  scans[2].t_ns = 300'000'000;
  scans[2].has_pose_covariance = true;
  scans[2].status = lio::ScanStatus::kFailed;  // failed: left out
  const std::string dir = testing::FreshTempDir("covariance_csv").string();
  OutputFiles files;
  WriteTrajectoryCovariance(dir, scans, &files);
  const std::string path = dir + "/trajectory_covariance.csv";
  std::ifstream f(path);
  std::string header, line, extra;
  ASSERT_TRUE(std::getline(f, header));
  EXPECT_EQ(header.substr(0, 33), "t,c_x_x,c_x_y,c_x_z,c_x_rx,c_x_ry");
  EXPECT_EQ(header.substr(header.size() - 15), "c_ry_rz,c_rz_rz");
  ASSERT_TRUE(std::getline(f, line));
  EXPECT_FALSE(std::getline(f, extra));
  EXPECT_EQ(line, "0.200000000,0,1,2,3,4,5,11,12,13,14,15,22,23,24,25,33,34,35,44,45,55");
}

// Pose T = Exp(ε)·T̂ with ε ~ N(0, Σ): the ROS covariance is that of [p; φ] (the position in
// the world frame and the rotation about the world's fixed axes). Monte Carlo, fixed seed:
// every entry within 5% of the diagonal scale.
TEST(CovarianceOutput, RosCovarianceIsThatOfPositionAndFixedAxisRotation) {
  const SE3 T(so3::Exp(Vec3(0.3, -0.5, 1.0)), Vec3(4.0, -2.0, 1.0));
  Vec6 sd;
  sd << 0.02, 0.03, 0.01, 0.004, 0.002, 0.006;
  const Mat6 S = sd.cwiseAbs2().asDiagonal();
  std::array<double, 36> ros = RosPoseCovariance(S, T);
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> R(ros.data());
  // A rotation about the world z axis by σ at position p moves it by σ·(ẑ × p): known value.
  EXPECT_NEAR(R(0, 0), sd[0] * sd[0] + std::pow(sd[4] * 1.0, 2) + std::pow(sd[5] * 2.0, 2), 1e-15);
  EXPECT_NEAR(R(5, 5), sd[5] * sd[5], 1e-15);
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  Mat6 empirical = Mat6::Zero();
  const int kDraws = 40000;
  for (int k = 0; k < kDraws; ++k) {
    Vec6 z;
    for (int i = 0; i < 6; ++i) z[i] = sd[i] * n(rng);
    const SE3 T_true = SE3::Exp(z) * T;
    Vec6 d;
    d.head<3>() = T_true.translation() - T.translation();
    d.tail<3>() = so3::Log(T_true.rotation() * T.rotation().transpose());
    empirical += d * d.transpose() / kDraws;
  }
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      EXPECT_NEAR(empirical(i, j), R(i, j), 0.05 * std::sqrt(R(i, i) * R(j, j))) << i << "," << j;
}

}  // namespace
}  // namespace ctlio::lioapp
