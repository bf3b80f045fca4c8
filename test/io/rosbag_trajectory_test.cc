// The same simulated sequence through ctlio's folder layout and through a ROS 1 bag gives the same
// trajectory: the bag path loses nothing the odometry uses (float32 points and uint32 ns offsets in
// both, float64 IMU, the extrinsic through /tf_static), so both sources hand the odometry the same
// data bit for bit. A short sparse sequence keeps it fast.
//
// The trajectories are compared to 1e-9 m. (They are equal: the window's marginalisation sums and
// removes residual blocks in the order they were added, not by address, so the odometry no longer
// depends on the heap layout; equal inputs are asserted exactly.)
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/temp_dir.h"
#include "common/test_paths.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::io {
namespace {

TEST(RosbagTrajectory, FolderAndBagGiveTheSameTrajectory) {
  const auto d = testing::FreshTempDir("rosbag_trajectory");
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 2);
  c.duration_s = 0.8;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;  // a bag cannot hold time 0
  {
    sim::SimulatedSource a(c), b(c);
    WriteSimFolder(a, (d / "folder").string());
    WriteRosbag(b, (d / "run.bag").string());
  }
  SimFolderReader folder((d / "folder").string());
  RosbagSource bag((d / "run.bag").string());
  // The two sources hand the odometry identical data, bit for bit.
  EXPECT_EQ(folder.ImuFromLidar().Matrix(), bag.ImuFromLidar().Matrix());
  {
    SimFolderReader f((d / "folder").string());
    RosbagSource r((d / "run.bag").string());
    ScanFrame a, b;
    size_t n = 0;
    while (f.Next(&a)) {
      ASSERT_TRUE(r.Next(&b));
      EXPECT_EQ(a.start_ns, b.start_ns);
      EXPECT_EQ(a.end_ns, b.end_ns);
      EXPECT_EQ(a.cloud.points, b.cloud.points);
      EXPECT_EQ(a.cloud.times_ns, b.cloud.times_ns);
      ASSERT_EQ(a.imu.size(), b.imu.size());
      for (size_t i = 0; i < a.imu.size(); ++i) {
        EXPECT_EQ(a.imu[i].t_ns, b.imu[i].t_ns);
        EXPECT_EQ(a.imu[i].gyro, b.imu[i].gyro);
        EXPECT_EQ(a.imu[i].accel, b.imu[i].accel);
      }
      ++n;
    }
    EXPECT_FALSE(r.Next(&b));
    EXPECT_GE(n, 7u);
  }
  lio::OdometryConfig config =
      lio::LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  // A bag carries no gravity magnitude: give the config the folder's (the simulator's) value.
  config.gravity = folder.Gravity().value();
  for (const auto method : {lio::LioMethod::kSingerLio, lio::LioMethod::kImuInput}) {
    config.method = method;
    SimFolderReader f((d / "folder").string());
    RosbagSource r((d / "run.bag").string());
    const lioapp::RunSummary a = lioapp::RunOdometry(f, config);
    const lioapp::RunSummary b = lioapp::RunOdometry(r, config);
    EXPECT_THAT(b.extrinsic_origin, ::testing::HasSubstr("/tf_static"));
    ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
    ASSERT_GE(a.trajectory.size(), 7u);
    double worst = 0.0;
    for (size_t k = 0; k < a.trajectory.size(); ++k) {
      EXPECT_EQ(a.trajectory[k].t_ns, b.trajectory[k].t_ns);
      worst = std::max(
          worst, (a.trajectory[k].pose.translation() - b.trajectory[k].pose.translation()).norm());
    }
    EXPECT_LT(worst, 1e-9) << lio::LioMethodName(method);
    // Not a degenerate pass: the run tracked the truth.
    ASSERT_TRUE(b.ate);
    EXPECT_LT(b.ate->rmse, 0.1);
  }
}

// A simulated sequence whose scan `empty` has no points and whose scan `instant` has every point at
// its stamp (a driver that wrote no per-point times): unusable scans of a bag.
class UnusableScans : public DataSource {
 public:
  UnusableScans(const sim::SimConfig& c, size_t empty, size_t instant)
      : source_(c), empty_(empty), instant_(instant) {}
  std::string Name() const override { return source_.Name(); }
  size_t NumScans() const override { return source_.NumScans(); }
  SE3 ImuFromLidar() const override { return source_.ImuFromLidar(); }
  std::optional<std::vector<StampedPose>> GroundTruth() const override {
    return source_.GroundTruth();
  }
  std::optional<double> Gravity() const override { return source_.Gravity(); }
  std::vector<ImuInfo> Imus() const override { return source_.Imus(); }
  bool Next(ScanFrame* f) override {
    if (!source_.Next(f)) return false;
    if (f->index == empty_) {
      PointCloud none;
      none.stamp_ns = f->cloud.stamp_ns;
      f->cloud = none;
    }
    if (f->index == instant_) {
      for (int64_t& t : f->cloud.times_ns) t = f->cloud.stamp_ns;
    }
    return true;
  }

 private:
  sim::SimulatedSource source_;
  size_t empty_, instant_;
};

// Unusable scans in a bag do not abort the run (it used to end with exit 2 and nothing written):
// the reader hands the empty one on with its nominal interval and counts it, gives the one with
// every point at the stamp times from the azimuth (its points lie at different azimuths: a sweep
// with a broken time field, point_time_check.h) and counts it too; the odometry estimates the
// rest and reports the empty one degenerate.
TEST(RosbagTrajectory, UnusableScansInABagDoNotAbortTheRun) {
  const auto d = testing::FreshTempDir("rosbag_unusable");
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 2);
  c.duration_s = 1.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
  {
    UnusableScans source(c, 5, 7);
    WriteRosbag(source, (d / "run.bag").string());
  }
  lio::OdometryConfig config =
      lio::LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  config.gravity = sim::SimulatedSource(c).Gravity().value();
  RosbagSource bag((d / "run.bag").string());
  const lioapp::RunSummary s = lioapp::RunOdometry(bag, config);
  EXPECT_EQ(bag.unusable_scans(), 1u);
  EXPECT_EQ(bag.retimed_scans(), 1u);
  ASSERT_EQ(s.scans.size(), sim::SimulatedSource(c).NumScans());
  EXPECT_GE(s.degenerate, 1);
  ASSERT_TRUE(s.ate);
  EXPECT_LT(s.ate->rmse, 0.1);
}

}  // namespace
}  // namespace ctlio::io
