// Settings that are legal but beyond any real IMU are warned about (config_plausibility.h): each
// bound trips just above it and not below, names the key, and the shipped configs trip none.
#include "ctlio/solvers/lio/config_plausibility.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "common/test_paths.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

TEST(ConfigPlausibility, TheDefaultsAndTheShippedConfigsArePlausible) {
  EXPECT_THAT(ImplausibleSettings(OdometryConfig{}), IsEmpty());
  for (const char* name : {"sim_lio.yaml", "newer_college_lio.yaml", "sim_lio_calibration.yaml"}) {
    const std::string path = ctlio::testing::SourceDir() + "/data/" + name;
    const OdometryConfig base = LoadOdometryConfig(path);
    for (LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput, LioMethod::kLidarGyro}) {
      EXPECT_THAT(ImplausibleSettings(base.ForMethod(m)), IsEmpty()) << name;
    }
  }
}

TEST(ConfigPlausibility, EachBoundTripsAboveItNamingTheKey) {
  OdometryConfig c;
  c.accel_variance = 99.0;  // σ just under 10 m/s²
  EXPECT_THAT(ImplausibleSettings(c), IsEmpty());
  c.accel_variance = 1e30;
  EXPECT_THAT(ImplausibleSettings(c),
              ElementsAre(HasSubstr("imu.accel_variance = 1e+30 (m/s^2)^2")));
  c = OdometryConfig{};
  c.accel_loss_scale = 1e30;
  EXPECT_THAT(ImplausibleSettings(c), ElementsAre(HasSubstr("(0 says that)")));
  c = OdometryConfig{};
  c.bias_accel_walk = 0.2;  // per 0.1 s: 1.41 m/s²/√s
  EXPECT_THAT(ImplausibleSettings(c), ElementsAre(HasSubstr("imu.bias_accel_walk")));
  c.bias_accel_walk = 0.09;  // 0.95 m/s²/√s
  EXPECT_THAT(ImplausibleSettings(c), IsEmpty());
  c.bias_walk_period = 1e30;
  EXPECT_THAT(ImplausibleSettings(c), ElementsAre(HasSubstr("imu.bias_walk_period")));
}

TEST(ConfigPlausibility, OnlyTheKeysTheMethodUsesAreChecked) {
  OdometryConfig c;
  c.accel_variance = 1e30;  // the baseline's accelerometer is input_accel_sigma
  c.method = LioMethod::kImuInput;
  EXPECT_THAT(ImplausibleSettings(c), IsEmpty());
  c.input_accel_sigma = 1e3;
  EXPECT_THAT(ImplausibleSettings(c), ElementsAre(HasSubstr("imu.input_accel_sigma")));
  c.method = LioMethod::kLidarOnly;  // no IMU at all
  EXPECT_THAT(ImplausibleSettings(c), IsEmpty());
}

}  // namespace
}  // namespace ctlio::lio
