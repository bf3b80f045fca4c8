// ScanWithoutImu (scan_without_imu.h): which scans it applies to, when a correction from the
// prediction is rejected, and that a restore after an implausible estimate removes exactly the
// scan's lidar blocks and puts back the predicted states.
// The larger registration budget is checked through the odometry (imu_dropout_test.cc).
#include "ctlio/solvers/lio/scan_without_imu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::lio {
namespace {

TEST(ScanWithoutImu, AppliesToGpMethodsOnScansWithoutImuResiduals) {
  ScanResult measured, unmeasured;
  measured.imu_residuals = 40;
  unmeasured.imu_residuals = 0;
  for (LioMethod m : {LioMethod::kSingerLio, LioMethod::kLidarGyro, LioMethod::kLidarOnly}) {
    EXPECT_TRUE(ScanWithoutImu::Applies(m, unmeasured)) << LioMethodName(m);
    EXPECT_FALSE(ScanWithoutImu::Applies(m, measured)) << LioMethodName(m);
  }
  // The baseline bridges its gaps its own way.
  EXPECT_FALSE(ScanWithoutImu::Applies(LioMethod::kImuInput, unmeasured));
}

TEST(ScanWithoutImu, RestoreRemovesTheLidarBlocksAndPutsBackThePrediction) {
  SlidingWindow window;
  const SE3 older(so3::Exp(Vec3(0.1, 0.0, 0.2)), Vec3(1, 2, 3));
  const SE3 predicted(so3::Exp(Vec3(0.0, 0.3, -0.1)), Vec3(4, 5, 6));
  window.AddPoseState(1, older);
  window.AddPoseState(2, predicted);
  window.AddVectorState(3, Eigen::Vector3d(0.5, -0.5, 1.0));
  const Mat6 I = Mat6::Identity();
  const ceres::ResidualBlockId kept =
      window.AddResidualBlock(new PosePrior(older, I), nullptr, {1});

  ScanWithoutImu scan;
  scan.Begin(true, {2, 3}, window);
  ASSERT_TRUE(scan.active());
  RegistrationSummary registered;
  registered.lidar_blocks.push_back(window.AddResidualBlock(
      new PosePrior(SE3(Mat3::Identity(), Vec3(40, 0, 0)), I), nullptr, {2}));
  window.Solve();  // the "registration" moves the newest pose 40 m away: implausible
  ASSERT_GT((window.Pose(2).translation() - predicted.translation()).norm(), 30.0);
  window.State(3)[0] = 7.0;
  const Eigen::VectorXd solved_older = window.Vector(1);

  ASSERT_TRUE(scan.Restore(registered, &window));
  EXPECT_EQ(window.num_residual_blocks(), 1);
  EXPECT_EQ(window.ResidualBlocksOf(1).front(), kept);
  EXPECT_TRUE(window.ResidualBlocksOf(2).empty());
  EXPECT_EQ((window.Pose(2).translation() - predicted.translation()).norm(), 0.0);
  EXPECT_LT((window.Pose(2).rotation() - predicted.rotation()).norm(), 1e-12);
  EXPECT_EQ(window.Vector(3), Eigen::Vector3d(0.5, -0.5, 1.0));
  EXPECT_EQ(window.Vector(1), solved_older);  // not the scan's state: left as solved
}

TEST(ScanWithoutImu, AScanWithImuIsLeftAlone) {
  SlidingWindow window;
  window.AddPoseState(2, SE3());
  ScanWithoutImu scan;
  scan.Begin(true, {2}, window);
  scan.Begin(false, {2}, window);  // the next scan has IMU samples: nothing kept from before
  EXPECT_FALSE(scan.active());
  RegistrationSummary registered;
  registered.lidar_blocks.push_back(window.AddResidualBlock(
      new PosePrior(SE3(Mat3::Identity(), Vec3(1, 0, 0)), Mat6::Identity()), nullptr, {2}));
  window.State(2)[0] = 9.0;
  EXPECT_FALSE(scan.Restore(registered, &window));
  EXPECT_EQ(window.num_residual_blocks(), 1);
  EXPECT_EQ(window.State(2)[0], 9.0);
}

// `result` with a correction of `m` metres and `rad` radians from its prediction.
ScanResult Corrected(double m, double rad, ScanStatus status = ScanStatus::kImuGap) {
  ScanResult r;
  r.status = status;
  r.correction_m = m;
  r.correction_rad = rad;
  if (status == ScanStatus::kImuGap) r.message = "IMU gap of 2 s";
  return r;
}

LidarFrontendOptions Limits(double m, double rad) {
  LidarFrontendOptions o;
  o.max_correction_without_imu = m;
  o.max_rotation_correction_without_imu = rad;
  return o;
}

TEST(ScanWithoutImu, RejectsACorrectionAboveTheLimitOnlyInAnOutageOfAnImuMethod) {
  SlidingWindow window;
  window.AddPoseState(2, SE3());
  ScanWithoutImu scan;
  scan.Begin(true, {2}, window);
  ScanResult result = Corrected(0.30, 0.0);
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.30, 0.0), &result));  // the limit passes
  result.correction_m = 0.31;
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.0, 0.0), &result));    // 0 = off
  EXPECT_FALSE(scan.RejectsCorrection(false, Limits(0.30, 0.0), &result));  // lidar_only
  EXPECT_EQ(result.status, ScanStatus::kImuGap);
  ASSERT_TRUE(scan.RejectsCorrection(true, Limits(0.30, 0.0), &result));
  EXPECT_EQ(result.status, ScanStatus::kDegenerate);
  EXPECT_NE(result.message.find("0.31 m from the prediction"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("lidar_frontend.max_correction_without_imu"), std::string::npos);
  EXPECT_NE(result.message.find("IMU gap of 2 s"), std::string::npos);  // the gap's reason kept

  ScanResult failed = Corrected(9.0, 1.0, ScanStatus::kFailed);
  // A divergence is reported as such, not as a rejection.
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.30, 0.1), &failed));
  EXPECT_EQ(failed.status, ScanStatus::kFailed);

  scan.Begin(false, {2}, window);  // a scan with IMU samples
  ScanResult measured = Corrected(9.0, 1.0, ScanStatus::kOk);
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.30, 0.1), &measured));
  EXPECT_EQ(measured.status, ScanStatus::kOk);
}

// A registration that turns an outage scan further than the rotation limit is rejected though
// it moved the pose less than the translation limit (the Pandar XT-32 box medium run whose
// 17° turn at 0.2 m the translation limit let through); each limit alone, 0 = off.
TEST(ScanWithoutImu, RejectsARotationAboveItsLimitWhateverTheTranslation) {
  SlidingWindow window;
  window.AddPoseState(2, SE3());
  ScanWithoutImu scan;
  scan.Begin(true, {2}, window);
  const double turn = 17.0 * M_PI / 180.0;
  ScanResult kept = Corrected(0.2, 0.1);
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.5, 0.1), &kept));  // the limit itself passes
  ScanResult off = Corrected(0.2, turn);
  EXPECT_FALSE(scan.RejectsCorrection(true, Limits(0.5, 0.0), &off));
  EXPECT_FALSE(scan.RejectsCorrection(false, Limits(0.5, 0.1), &off));  // lidar_only
  ScanResult turned = Corrected(0.2, turn);
  ASSERT_TRUE(scan.RejectsCorrection(true, Limits(0.5, 0.1), &turned));
  EXPECT_EQ(turned.status, ScanStatus::kDegenerate);
  EXPECT_NE(turned.message.find("turned the pose 0.296"), std::string::npos) << turned.message;
  EXPECT_NE(turned.message.find("lidar_frontend.max_rotation_correction_without_imu"),
            std::string::npos);
  ScanResult rotation_off = Corrected(0.6, 0.0);  // the translation limit alone still holds
  EXPECT_TRUE(scan.RejectsCorrection(true, Limits(0.5, 0.0), &rotation_off));
  ScanResult nan = Corrected(0.1, std::nan(""));  // not a finite turn: rejected
  EXPECT_TRUE(scan.RejectsCorrection(true, Limits(0.5, 0.1), &nan));
  // The limit is an angle: in [0, π].
  EXPECT_NO_THROW(Limits(0.5, M_PI).Validate());
  for (const double bad : {-0.1, 4.0, std::nan("")}) {
    EXPECT_THROW(Limits(0.5, bad).Validate(), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace ctlio::lio
