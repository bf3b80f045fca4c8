// imu.accel_loss_relax_bias_sigma / imu.accel_loss_relaxed_scale (accel_loss_schedule.h): the
// accelerometer's Cauchy loss is held while the window's marginal σ of the accelerometer bias is
// above the threshold and relaxed, for good, once it is below.
#include "ctlio/solvers/lio/accel_loss_schedule.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/sim_lio.h"
#include "common/write_temp.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

TEST(AccelLossSchedule, HeldAboveTheThresholdRelaxedBelowAndLatched) {
  AccelLossSchedule s(1.0, 0.05, 3.0, 2);
  EXPECT_TRUE(s.Watching(0));
  // σ 0.1 on one axis, 0.01 on the others: the largest axis decides, so held.
  s.Observe(0, Vec3(0.01, 0.1, 0.01).cwiseAbs2().asDiagonal());
  EXPECT_FALSE(s.relaxed(0));
  EXPECT_DOUBLE_EQ(s.scale(0), 1.0);
  EXPECT_NEAR(s.last_sigma(0), 0.1, 1e-12);
  s.Observe(0, Vec3(0.04, 0.049, 0.03).cwiseAbs2().asDiagonal());
  EXPECT_TRUE(s.relaxed(0));
  EXPECT_DOUBLE_EQ(s.scale(0), 3.0);
  EXPECT_FALSE(s.Watching(0));
  // Latched: a later, larger σ does not bring the loss back.
  s.Observe(0, Mat3::Identity());
  EXPECT_TRUE(s.relaxed(0));
  // Per IMU: the second is still held.
  EXPECT_FALSE(s.relaxed(1));
  EXPECT_DOUBLE_EQ(s.scale(1), 1.0);
}

TEST(AccelLossSchedule, ACorrelatedCovarianceIsJudgedByItsLargestAxis) {
  // Diagonal 0.04² on every axis but strongly correlated: the largest σ is along (1, 1, 0).
  Mat3 P = Mat3::Identity() * 0.0016;
  P(0, 1) = P(1, 0) = 0.0015;
  EXPECT_NEAR(AccelLossSchedule::LargestSigma(P), std::sqrt(0.0031), 1e-12);
  AccelLossSchedule s(1.0, 0.05, 0.0, 1);
  s.Observe(0, P);  // 0.0557 > 0.05 although every diagonal σ is 0.04
  EXPECT_FALSE(s.relaxed(0));
}

TEST(AccelLossSchedule, NoEvidenceRelaxesNothingAndOffNeverWatches) {
  AccelLossSchedule s(1.0, 0.05, 0.0, 1);
  // A pseudo-inverse's unobserved direction reads 0: not "known".
  s.Observe(0, Mat3::Zero());
  EXPECT_FALSE(s.relaxed(0));
  Mat3 bad = Mat3::Identity() * 1e-6;
  bad(2, 2) = std::numeric_limits<double>::quiet_NaN();
  s.Observe(0, bad);
  EXPECT_FALSE(s.relaxed(0));
  AccelLossSchedule off(1.0, 0.0, 0.0, 1);
  EXPECT_FALSE(off.Watching(0));
  off.Observe(0, Mat3::Identity() * 1e-8);
  EXPECT_FALSE(off.relaxed(0));
  EXPECT_DOUBLE_EQ(off.scale(0), 1.0);
}

TEST(AccelLossSchedule, ConfigKeysAreRangeChecked) {
  OdometryConfig c = testing::SimLioConfig();
  for (double bad : {-0.01, 10.5, std::numeric_limits<double>::quiet_NaN()}) {
    OdometryConfig x = c;
    x.accel_loss_relax_bias_sigma = bad;
    EXPECT_THROW(x.Validate(), std::invalid_argument) << bad;
  }
  for (double bad : {-1.0, 1e4}) {
    OdometryConfig x = c;
    x.accel_loss_relaxed_scale = bad;
    EXPECT_THROW(x.Validate(), std::invalid_argument) << bad;
  }
  c.accel_loss_relax_bias_sigma = 0.05;
  c.accel_loss_relaxed_scale = 3.0;
  EXPECT_NO_THROW(c.Validate());
}

TEST(AccelLossSchedule, TheKeysAreReadFromYamlAndABadOneNamesTheFile) {
  const OdometryConfig c = LoadOdometryConfig(testing::WriteTemp(
      "relax.yaml", "imu:\n  accel_loss_relax_bias_sigma: 0.04\n  accel_loss_relaxed_scale: 3\n"));
  EXPECT_DOUBLE_EQ(c.accel_loss_relax_bias_sigma, 0.04);
  EXPECT_DOUBLE_EQ(c.accel_loss_relaxed_scale, 3.0);
  EXPECT_DOUBLE_EQ(OdometryConfig().accel_loss_relax_bias_sigma, 0.0);  // off by default
  const std::string path =
      testing::WriteTemp("relax_bad.yaml", "imu:\n  accel_loss_relax_bias_sigma: -1\n");
  try {
    LoadOdometryConfig(path);
    ADD_FAILURE() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("imu.accel_loss_relax_bias_sigma"), std::string::npos)
        << e.what();
  }
}

// 1.5 s of walking at tuning index 100, 16 beams, every 8th firing.
sim::SimConfig Walk() { return testing::ShortSequenceAtIndex100(sim::Regime::kWalking); }

OdometryConfig Config(const std::function<void(OdometryConfig*)>& change) {
  OdometryConfig c = testing::SimLioConfig();
  c.method = LioMethod::kSingerLio;
  change(&c);
  for (auto& [name, method_config] : c.per_method) {
    auto copy = std::make_shared<OdometryConfig>(*method_config);
    change(copy.get());
    method_config = std::move(copy);
  }
  return c;
}

lioapp::RunSummary RunWalk(const std::function<void(OdometryConfig*)>& change) {
  sim::SimulatedSource source(Walk());
  return lioapp::RunOdometry(source, Config(change));
}

double MaxPositionDifference(const lioapp::RunSummary& a, const lioapp::RunSummary& b) {
  EXPECT_EQ(a.trajectory.size(), b.trajectory.size());
  double d = 0.0;
  for (size_t i = 0; i < std::min(a.trajectory.size(), b.trajectory.size()); ++i) {
    d = std::max(d, (a.trajectory[i].pose.translation() - b.trajectory[i].pose.translation())
                        .lpNorm<Eigen::Infinity>());
  }
  return d;
}

// The schedule in the odometry: before the threshold is reached the run is the loss-on run bit for
// bit; the scan the marginal σ first falls below the threshold, and every scan after it, takes the
// relaxed scale; a threshold the start-up prior already meets is the relaxed scale all run long.
TEST(AccelLossSchedule, TheOdometryRelaxesTheLossOnceTheBiasSigmaIsBelowTheThreshold) {
  const lioapp::RunSummary on = RunWalk([](OdometryConfig*) {});
  const lioapp::RunSummary none = RunWalk([](OdometryConfig* c) { c->accel_loss_scale = 0.0; });
  // Never reached (the σ cannot fall to 1e-6 m/s²): the loss-on run, bit for bit.
  const lioapp::RunSummary never = RunWalk([](OdometryConfig* c) {
    c->accel_loss_relax_bias_sigma = 1e-6;
    c->accel_loss_relaxed_scale = 0.0;
  });
  ASSERT_EQ(on.failed, 0);
  ASSERT_GE(on.scans.size(), 14u);
  EXPECT_EQ(MaxPositionDifference(on, never), 0.0);
  // The σ the schedule read, scan by scan, from the start-up prior's √0.1 = 0.32 m/s² down.
  std::vector<double> sigma;
  std::vector<int> scan_of;  // the scan each σ was read before
  for (size_t i = 0; i < never.scans.size(); ++i) {
    EXPECT_FALSE(never.scans[i].accel_loss_relaxed);
    if (never.scans[i].accel_bias_sigma <= 0.0) continue;
    sigma.push_back(never.scans[i].accel_bias_sigma);
    scan_of.push_back(static_cast<int>(i));
  }
  ASSERT_GE(sigma.size(), 10u);
  EXPECT_NEAR(sigma.front(), std::sqrt(0.1), 1e-6);  // the initial prior alone
  EXPECT_LT(sigma.back(), 0.5 * sigma.front());      // the accelerometer observed it
  for (double s : sigma) std::printf("%.4f ", s);
  std::printf("\n");

  // A threshold between the 10th and the 11th σ (measured 0.247 and 0.207 m/s²: the walk has
  // begun to observe the bias).
  const double threshold = 0.5 * (sigma[9] + sigma[10]);
  ASSERT_GT(sigma[9], sigma[10]);
  for (int i = 0; i < 10; ++i) ASSERT_GT(sigma[i], threshold) << i;
  const lioapp::RunSummary relaxing = RunWalk([&](OdometryConfig* c) {
    c->accel_loss_relax_bias_sigma = threshold;
    c->accel_loss_relaxed_scale = 0.0;
  });
  int first_relaxed = -1;
  for (size_t i = 0; i < relaxing.scans.size(); ++i) {
    const bool relaxed = relaxing.scans[i].accel_loss_relaxed;
    if (relaxed && first_relaxed < 0) first_relaxed = static_cast<int>(i);
    if (first_relaxed >= 0) EXPECT_TRUE(relaxed) << "scan " << i << ": latched";
  }
  // The first scan whose σ was below the threshold, and none before it.
  ASSERT_EQ(first_relaxed, scan_of[10]);
  // Held while above: the same estimates as the loss-on run up to the scan before it relaxed.
  for (int i = 0; i < first_relaxed; ++i) {
    EXPECT_EQ(relaxing.scans[i].T_mr.translation(), on.scans[i].T_mr.translation()) << i;
  }
  // Relaxed below it: the estimate departs from the loss-on run from that scan on.
  double after = 0.0;
  for (size_t i = first_relaxed; i < relaxing.scans.size(); ++i) {
    after = std::max(
        after, (relaxing.scans[i].T_mr.translation() - on.scans[i].T_mr.translation()).norm());
  }
  EXPECT_GT(after, 1e-9);

  // A threshold above the start-up σ: no loss from the first scan, as with accel_loss_scale 0.
  const lioapp::RunSummary at_once = RunWalk([](OdometryConfig* c) {
    c->accel_loss_relax_bias_sigma = 1.0;
    c->accel_loss_relaxed_scale = 0.0;
  });
  EXPECT_EQ(MaxPositionDifference(at_once, none), 0.0);
  EXPECT_GT(MaxPositionDifference(at_once, on), 1e-9);
}

}  // namespace
}  // namespace ctlio::lio
