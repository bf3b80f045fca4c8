// imu.residual_blocks (OdometryConfig::imu_residual_blocks): the odometry with one IMU block per
// knot interval and IMU (imu/imu_interval_batch.h) gives the trajectory of one gyro and one
// accelerometer block per sample — the same cost, gradient and Gauss–Newton step up to rounding,
// so the same solves and marginal priors — for Singer-LIO (with two knots per sweep, a held and an
// estimated clock offset) and lidar_gyro; and the IMU consistency check's χ² per scan is the same.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

// 1.5 s of medium motion, 16 beams, every 8th firing: the window fills and marginalises.
sim::SimConfig Sequence() {
  sim::SimConfig c = testing::ShortSparseSequence();
  c.duration_s = 1.5;
  return c;
}

// The config with `blocks` in the top level and in every per-method copy.
OdometryConfig Config(LioMethod method, const std::string& blocks,
                      const std::function<void(OdometryConfig*)>& change) {
  OdometryConfig c = testing::SimLioConfig();
  c.method = method;
  const auto apply = [&](OdometryConfig* x) {
    x->imu_residual_blocks = blocks;
    change(x);
  };
  apply(&c);
  for (auto& [name, method_config] : c.per_method) {
    auto copy = std::make_shared<OdometryConfig>(*method_config);
    apply(copy.get());
    method_config = std::move(copy);
  }
  return c;
}

struct Variant {
  std::string name;
  LioMethod method;
  std::function<void(OdometryConfig*)> change;
};

// Measured largest differences between the two forms over these runs (rounding carried through
// the solves): position 1.8e-8 m, rotation 9.1e-10 rad, χ² 5.5e-8 relative (lidar_gyro 3e-17 m).
// Bound: 1e-6 m, 1e-7 rad, 1e-5 relative.
TEST(ImuResidualBlocks, IntervalAndSampleBlocksGiveTheSameTrajectory) {
  const std::vector<Variant> variants = {
      {"singer_lio", LioMethod::kSingerLio, [](OdometryConfig*) {}},
      {"singer_lio two knots per sweep", LioMethod::kSingerLio,
       [](OdometryConfig* c) { c->knots_per_scan = 2; }},
      {"singer_lio held clock offset", LioMethod::kSingerLio,
       [](OdometryConfig* c) { c->calibration.time_offset_s = {0.003}; }},
      {"singer_lio estimated clock offset", LioMethod::kSingerLio,
       [](OdometryConfig* c) { c->calibration.estimate_time_offset = true; }},
      {"lidar_gyro", LioMethod::kLidarGyro, [](OdometryConfig*) {}},
  };
  for (const Variant& v : variants) {
    sim::SimulatedSource sample_source(Sequence()), interval_source(Sequence());
    const lioapp::RunSummary sample =
        lioapp::RunOdometry(sample_source, Config(v.method, "sample", v.change));
    const lioapp::RunSummary interval =
        lioapp::RunOdometry(interval_source, Config(v.method, "interval", v.change));
    ASSERT_EQ(sample.failed, 0) << v.name;
    ASSERT_EQ(interval.failed, 0) << v.name;
    ASSERT_EQ(sample.trajectory.size(), interval.trajectory.size()) << v.name;
    ASSERT_GE(sample.trajectory.size(), 14u) << v.name;
    double position = 0.0, rotation = 0.0, chi2 = 0.0;
    for (size_t i = 0; i < sample.trajectory.size(); ++i) {
      const SE3 d = sample.trajectory[i].pose.Inverse() * interval.trajectory[i].pose;
      position = std::max(position, d.translation().norm());
      rotation = std::max(rotation, d.Log().tail<3>().norm());
    }
    ASSERT_EQ(sample.scans.size(), interval.scans.size()) << v.name;
    int with_chi2 = 0;
    for (size_t i = 0; i < sample.scans.size(); ++i) {
      const ScanResult &a = sample.scans[i], &b = interval.scans[i];
      EXPECT_EQ(a.imu_residuals, b.imu_residuals) << v.name << " scan " << i;
      EXPECT_EQ(a.accel_dof, b.accel_dof) << v.name << " scan " << i;
      EXPECT_EQ(a.gyro_dof, b.gyro_dof) << v.name << " scan " << i;
      for (const auto& [x, y] :
           {std::pair{a.accel_chi2, b.accel_chi2}, {a.gyro_chi2, b.gyro_chi2}}) {
        chi2 = std::max(chi2, std::abs(x - y) / std::max(1e-12, std::abs(x)));
      }
      with_chi2 += a.gyro_dof > 0;
    }
    EXPECT_GE(with_chi2, 10) << v.name;
    EXPECT_LT(position, 1e-6) << v.name;
    EXPECT_LT(rotation, 1e-7) << v.name;
    EXPECT_LT(chi2, 1e-5) << v.name;
    std::printf("%s: position %.3g m, rotation %.3g rad, chi2 %.3g relative\n", v.name.c_str(),
                position, rotation, chi2);
  }
}

TEST(ImuResidualBlocks, ConfigRejectsAnUnknownForm) {
  OdometryConfig c = testing::SimLioConfig();
  c.imu_residual_blocks = "samples";
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c.imu_residual_blocks = "sample";
  EXPECT_NO_THROW(c.Validate());
}

}  // namespace
}  // namespace ctlio::lio
