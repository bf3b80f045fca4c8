// Issue 41's equality: the same simulated sequence written as a ctlio folder, a ROS 1 bag, ROS 2
// MCAP bags (chunks uncompressed, zstd, lz4) and a ROS 2 SQLite bag hands the odometry the same
// frames bit for bit (points, per-point times, IMU), the same extrinsic and ground truth — each bag
// opened by OpenDataset as its folder and as its single storage file — and the same trajectory
// (to 1e-9 m) for Singer-LIO and the baseline.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "common/test_paths.h"
#include "ctlio/io/bag_writer.h"
#include "ctlio/io/cdr_messages.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "io/same_frames.h"
#include "lio/run_odometry.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

sim::SimConfig Sequence() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 2);
  c.duration_s = 0.8;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;  // a ROS 1 bag cannot hold time 0
  return c;
}

struct Written {
  fs::path folder;
  std::vector<std::string> bags;  // ROS 1 bag, then the ROS 2 bag folders
};

const Written& WriteAll() {
  static const Written w = [] {
    Written out;
    const fs::path d = testing::FreshTempDir("ros2_bag_trajectory");
    out.folder = d / "folder";
    sim::SimulatedSource a(Sequence());
    WriteSimFolder(a, out.folder.string());
    out.bags.push_back((d / "run.bag").string());
    sim::SimulatedSource b(Sequence());
    WriteRosbag(b, out.bags.back());
    const std::pair<const char*, Ros2WriteOptions> ros2[] = {
        {"mcap_none", {ros2::Ros2Storage::kMcap, ros2::Ros2Compression::kNone}},
        {"mcap_zstd", {ros2::Ros2Storage::kMcap, ros2::Ros2Compression::kZstd}},
        {"mcap_lz4", {ros2::Ros2Storage::kMcap, ros2::Ros2Compression::kLz4}},
        {"sqlite3", {ros2::Ros2Storage::kSqlite3, ros2::Ros2Compression::kNone}}};
    for (const auto& [name, options] : ros2) {
      out.bags.push_back((d / name).string());
      sim::SimulatedSource s(Sequence());
      WriteRos2Bag(s, out.bags.back(), {}, options);
    }
    return out;
  }();
  return w;
}

// The one storage file of a bag folder.
std::string StorageFile(const fs::path& folder) {
  for (const auto& e : fs::directory_iterator(folder)) {
    if (e.path().extension() == ".mcap" || e.path().extension() == ".db3") return e.path().string();
  }
  return "";
}

void ExpectSameFrames(DataSource& expected, DataSource& read) {
  EXPECT_EQ(read.ImuFromLidar().Matrix(), expected.ImuFromLidar().Matrix());
  EXPECT_GE(testing::ExpectSameFrames(expected, read), 7u);
  EXPECT_TRUE(expected.GroundTruth() && read.GroundTruth());
}

TEST(Ros2BagTrajectory, EveryLayoutHandsTheOdometryTheSameFrames) {
  const Written& w = WriteAll();
  for (size_t k = 0; k < w.bags.size(); ++k) {
    std::vector<std::string> paths = {w.bags[k]};
    if (k > 0) paths.push_back(StorageFile(w.bags[k]));  // a ROS 2 bag's file alone
    for (const std::string& path : paths) {
      SCOPED_TRACE(path);
      ASSERT_FALSE(path.empty());
      SimFolderReader folder(w.folder.string());
      const std::unique_ptr<DataSource> read = OpenDataset(path);
      EXPECT_THAT(read->Name(), StartsWith(k == 0 ? "rosbag:" : "ros2bag:"));
      EXPECT_THAT(read->ExtrinsicOrigin(), HasSubstr("/tf_static (os_imu → os_lidar)"));
      ExpectSameFrames(folder, *read);
    }
  }
}

TEST(Ros2BagTrajectory, FolderAndRos2BagsGiveTheSameTrajectory) {
  const Written& w = WriteAll();
  lio::OdometryConfig config =
      lio::LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  config.gravity = SimFolderReader(w.folder.string()).Gravity().value();
  for (const auto method : {lio::LioMethod::kSingerLio, lio::LioMethod::kImuInput}) {
    config.method = method;
    SimFolderReader f(w.folder.string());
    const lioapp::RunSummary a = lioapp::RunOdometry(f, config);
    ASSERT_GE(a.trajectory.size(), 7u);
    for (size_t k = 1; k < w.bags.size(); ++k) {
      SCOPED_TRACE(w.bags[k]);
      const std::unique_ptr<DataSource> r = OpenDataset(w.bags[k]);
      const lioapp::RunSummary b = lioapp::RunOdometry(*r, config);
      ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
      double worst = 0.0;
      for (size_t i = 0; i < a.trajectory.size(); ++i) {
        EXPECT_EQ(a.trajectory[i].t_ns, b.trajectory[i].t_ns);
        worst = std::max(
            worst,
            (a.trajectory[i].pose.translation() - b.trajectory[i].pose.translation()).norm());
      }
      EXPECT_LT(worst, 1e-9) << lio::LioMethodName(method);
      ASSERT_TRUE(b.ate);
      EXPECT_LT(b.ate->rmse, 0.1);
    }
  }
}

// ctlio_odometry --write_bag on a ROS 2 input: the estimate as nav_msgs/msg/Odometry in a ROS 2
// bag folder, read back exactly (float64 poses, ns stamps).
TEST(Ros2BagTrajectory, OdometryBagHoldsTheTrajectory) {
  const fs::path d = testing::FreshTempDir("ros2_odometry_bag");
  const auto truth = *sim::SimulatedSource(Sequence()).GroundTruth();
  WriteOdometryRos2Bag((d / "trajectory_bag").string(), truth);
  ros2::Ros2BagReader reader((d / "trajectory_bag").string());
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].name, "/ctlio/odometry");
  EXPECT_EQ(reader.topics()[0].type, "nav_msgs/msg/Odometry");
  ros2::Ros2Message m;
  size_t n = 0;
  while (reader.Next(&m)) {
    ASSERT_LT(n, truth.size());
    nav_msgs::Odometry o;
    ros2::DecodeCdr(m.data.data(), m.data.size(), reader.Where() + ": ", &o);
    EXPECT_EQ(m.log_time_ns, truth[n].t_ns);
    EXPECT_EQ(int64_t(o.header.stamp.toNSec()), truth[n].t_ns);
    EXPECT_EQ(o.header.frame_id, "map");
    EXPECT_EQ(o.child_frame_id, "os_lidar");
    const auto& p = o.pose.pose;
    EXPECT_EQ(Vec3(p.position.x, p.position.y, p.position.z), truth[n].pose.translation());
    const Eigen::Quaterniond q(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
    EXPECT_LT((q.toRotationMatrix() - truth[n].pose.rotation()).norm(), 1e-14);  // via a quaternion
    ++n;
  }
  EXPECT_EQ(n, truth.size());
}

}  // namespace
}  // namespace ctlio::io
