// Degeneracy end to end (docs/experiments/worlds-and-degeneracy.md): short, reduced runs (3 s, 16
// beams, every 4th firing) of the walking regime in the corridor and the park, sequence index 100
// (the experiment reports indices 0–9). In the corridor the lidar term leaves the axis
// unconstrained: every method detects it per scan; Singer-LIO, the baseline and lidar_gyro stay
// `ok` (the prior and the IMU carry the axis, with more information along it than the lidar) and
// within the stated drift; lidar_only reports the scans `degenerate` and keeps its prediction along
// the axis instead of inventing motion. In the park Singer-LIO stays within its drift bound and
// lidar_only is flagged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

sim::SimConfig Walk(sim::WorldKind world) {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kWalking, 100, sim::kExperimentSeed, world);
  c.duration_s = 3.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 4;
  return c;
}

OdometryConfig Config(LioMethod method) {
  OdometryConfig c = testing::SimLioConfig();
  return c.ForMethod(method);
}

// Registered scans (all but the first, which builds the map) and those with a degenerate
// direction.
struct Counts {
  int registered = 0, with_direction = 0, status_degenerate = 0;
};
Counts Count(const lioapp::RunSummary& run) {
  Counts c;
  for (size_t i = 1; i < run.scans.size(); ++i) {
    const ScanResult& r = run.scans[i];
    ++c.registered;
    c.with_direction += r.degeneracy.num_degenerate() > 0;
    c.status_degenerate += r.status == ScanStatus::kDegenerate;
  }
  return c;
}

// Measured on this sequence (docs/experiments/worlds-and-degeneracy.md): degenerate directions (all
// along the axis) in 12 / 14 / 15 of 29 registered scans (singer_lio / imu_input / lidar_gyro; the
// corner behind the start constrains the axis in the others); whitened information along the axis,
// median of the flagged scans, prior vs lidar: 8.7e3 vs 522 (Singer-LIO), 533 vs 162
// (baseline), 9.2 vs 207 (lidar_gyro: no accelerometer, only the GP prior holds the axis); ATE
// 0.018 / 0.28 / 0.10 m, drift per 100 m 0.97 / 20.5 / 3.3 m. The bounds leave ~2.5× margin and
// separate a carried axis from the lidar_only failure (several metres).
TEST(DegenerateWorlds, CorridorAxisIsDetectedAndCarriedByThePriorAndTheImu) {
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput, LioMethod::kLidarGyro}) {
    sim::SimulatedSource source(Walk(sim::WorldKind::kCorridor));
    const lioapp::RunSummary run = lioapp::RunOdometry(source, Config(m));
    const std::string name = LioMethodName(m);
    ASSERT_TRUE(run.ate.has_value() && run.drift_per_100m.has_value()) << name;
    EXPECT_EQ(run.failed, 0) << name << ": " << run.first_failure;
    const Counts c = Count(run);
    EXPECT_GE(c.with_direction, 8) << name;
    EXPECT_EQ(c.status_degenerate, 0) << name;  // with an IMU the scans stay ok
    EXPECT_EQ(run.degenerate_direction_scans, c.with_direction) << name;
    std::vector<double> ratio;
    for (size_t i = 1; i < run.scans.size(); ++i) {
      const DegeneracyReport& d = run.scans[i].degeneracy;
      if (d.num_degenerate() == 0) continue;
      EXPECT_EQ(d.DirectionString().substr(0, 2), "t:") << name << " scan " << i;
      EXPECT_FALSE(d.remapped);
      EXPECT_GT(d.prior_information, 0.0);
      ratio.push_back(d.prior_information / std::max(d.lidar_information, 1e-12));
    }
    std::sort(ratio.begin(), ratio.end());
    if (m != LioMethod::kLidarGyro && !ratio.empty()) {
      EXPECT_GT(ratio[ratio.size() / 2], 1.0) << name << ": the prior and the IMU hold the axis";
    }
    const double ate_bound = m == LioMethod::kSingerLio  ? 0.05
                             : m == LioMethod::kImuInput ? 0.6
                                                         : 0.3;
    const double drift_bound = m == LioMethod::kSingerLio  ? 2.5
                               : m == LioMethod::kImuInput ? 40.0
                                                           : 8.0;
    EXPECT_LT(run.ate->rmse, ate_bound) << name;
    EXPECT_LT(*run.drift_per_100m, drift_bound) << name;
  }
}

// lidar_only (measured: 15 of 28 registered scans degenerate, ATE 8.9 m with the remapping, 0.53 m
// without it: docs/experiments/worlds-and-degeneracy.md explains the difference).
TEST(DegenerateWorlds, LidarOnlyReportsTheCorridorScansDegenerate) {
  sim::SimulatedSource source(Walk(sim::WorldKind::kCorridor));
  const lioapp::RunSummary run = lioapp::RunOdometry(source, Config(LioMethod::kLidarOnly));
  const Counts c = Count(run);
  EXPECT_GE(c.status_degenerate, 8);
  EXPECT_EQ(run.degenerate, c.status_degenerate);
  for (size_t i = 1; i < run.scans.size(); ++i) {
    const ScanResult& r = run.scans[i];
    if (r.degeneracy.num_degenerate() > 0 && r.status != ScanStatus::kFailed) {
      EXPECT_EQ(r.status, ScanStatus::kDegenerate) << "scan " << i << ": " << r.message;
    }
    if (r.status != ScanStatus::kDegenerate) continue;
    EXPECT_TRUE(r.degeneracy.remapped);
    EXPECT_NE(r.message.find("degenerate direction"), std::string::npos) << r.message;
    // The map frame is the start's robot frame, heading along the first straight: the degenerate
    // direction, moved into the map frame, is that axis (checked over the first 2 s: later
    // lidar_only's estimate, drifted by metres, no longer gives a trustworthy rotation).
    if (i > 20) continue;
    // A scan degenerate for another reason (too few associations) has no direction to check.
    ASSERT_FALSE(r.degeneracy.directions.empty()) << "scan " << i << ": " << r.message;
    const Vec3 u_map = r.T_mr.rotation() * r.degeneracy.directions[0].head<3>();
    EXPECT_GT(std::abs(u_map.x()), 0.8) << "scan " << i << ": " << u_map.transpose();
  }
}

// Park (measured: Singer-LIO 0.062 m ATE, 4.1 m per 100 m over this 4 m walk, 20 of 29 scans with
// a degenerate horizontal direction; lidar_only 15 scans degenerate).
TEST(DegenerateWorlds, ParkDriftOfSingerLioIsBoundedAndLidarOnlyIsFlagged) {
  {
    sim::SimulatedSource source(Walk(sim::WorldKind::kPark));
    const lioapp::RunSummary run = lioapp::RunOdometry(source, Config(LioMethod::kSingerLio));
    ASSERT_TRUE(run.ate.has_value() && run.drift_per_100m.has_value());
    EXPECT_EQ(run.failed, 0) << run.first_failure;
    EXPECT_LT(run.ate->rmse, 0.15);
    EXPECT_LT(*run.drift_per_100m, 10.0);
  }
  sim::SimulatedSource source(Walk(sim::WorldKind::kPark));
  const lioapp::RunSummary run = lioapp::RunOdometry(source, Config(LioMethod::kLidarOnly));
  EXPECT_GE(run.degenerate, 5);
}

}  // namespace
}  // namespace ctlio::lio
