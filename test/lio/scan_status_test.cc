#include "ctlio/solvers/lio/scan_status.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ctlio::lio {
namespace {

TEST(ScanStatus, AJumpAboveTheLimitOrNotFiniteFailsTheScanAndSaysBy) {
  ScanResult ok;
  EXPECT_TRUE(CheckPlausibleJump(4.9, true, 5.0, &ok));
  EXPECT_EQ(ok.status, ScanStatus::kOk);
  EXPECT_TRUE(ok.message.empty());

  ScanResult far;
  EXPECT_FALSE(CheckPlausibleJump(7.5, true, 5.0, &far));
  EXPECT_EQ(far.status, ScanStatus::kFailed);
  EXPECT_NE(far.message.find("7.5 m"), std::string::npos) << far.message;
  EXPECT_NE(far.message.find("limit 5 m"), std::string::npos) << far.message;

  // A NaN pose compares false with every limit: it must fail by the finiteness flag.
  ScanResult nan;
  EXPECT_FALSE(CheckPlausibleJump(std::numeric_limits<double>::quiet_NaN(), false, 5.0, &nan));
  EXPECT_EQ(nan.status, ScanStatus::kFailed);
}

TEST(ScanStatus, TooFewAssociationsNamesCountAndWhatCarriesTheState) {
  ScanResult with_imu;
  with_imu.associations = 12;
  MarkTooFewAssociations(50, true, &with_imu);
  EXPECT_EQ(with_imu.status, ScanStatus::kDegenerate);
  EXPECT_NE(with_imu.message.find("only 12 plane associations (need 50)"), std::string::npos);
  EXPECT_NE(with_imu.message.find("the prior and the IMU carry"), std::string::npos);

  ScanResult without_imu;
  MarkTooFewAssociations(50, false, &without_imu);
  EXPECT_NE(without_imu.message.find("the prior carries"), std::string::npos);
}

TEST(ScanStatus, AScanAlreadyNotOkKeepsItsStatusAndMessage) {
  ScanResult gapped;
  gapped.status = ScanStatus::kImuGap;
  gapped.message = "IMU gap";
  MarkTooFewAssociations(50, true, &gapped);
  MarkDegenerateDirections(&gapped);
  EXPECT_EQ(gapped.status, ScanStatus::kImuGap);
  EXPECT_EQ(gapped.message, "IMU gap");
}

TEST(ScanStatus, DegenerateDirectionsSayWhetherThePredictionWasKept) {
  ScanResult remapped;
  remapped.degeneracy.directions.push_back(Vec6::UnitX());
  remapped.degeneracy.remapped = true;
  MarkDegenerateDirections(&remapped);
  EXPECT_EQ(remapped.status, ScanStatus::kDegenerate);
  EXPECT_NE(remapped.message.find("prediction is kept"), std::string::npos) << remapped.message;

  ScanResult kept_lidar;
  kept_lidar.degeneracy.directions.push_back(Vec6::UnitX());
  MarkDegenerateDirections(&kept_lidar);
  EXPECT_NE(kept_lidar.message.find("remap off"), std::string::npos) << kept_lidar.message;
}

}  // namespace
}  // namespace ctlio::lio
