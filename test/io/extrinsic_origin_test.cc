// Issue 40: where a bag's extrinsic is a guess — a preset recognised from the topic names while
// the bag's /tf_static does not connect the IMU and lidar frames — the origin says so and a
// warning is logged; a /tf_static that connects them is used without a word.
#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <filesystem>
#include <mutex>

#include "common/temp_dir.h"
#include "common/warning_sink.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using ::ctlio::testing::WarningSink;

// Newer College 2020 topic names; /tf_static with one edge parent → child.
void WriteBag(const std::string& path, const std::string& parent, const std::string& child) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped e;
  e.header.frame_id = parent;
  e.child_frame_id = child;
  e.transform.rotation.w = 1;
  e.transform.translation.x = 0.2;
  tf.transforms.push_back(e);
  bag.write("/tf_static", ros::Time(0.001), tf);
  for (int64_t t = 10'000'000; t <= 500'000'000; t += 10'000'000) {
    sensor_msgs::Imu m;
    m.header.stamp.fromNSec(uint64_t(t));
    m.header.frame_id = "os1_imu";
    m.linear_acceleration.z = 9.81;
    bag.write("/os1_cloud_node/imu", m.header.stamp, m);
  }
  PointCloud c;
  c.stamp_ns = 200'000'000;
  for (int i = 0; i < 10; ++i) {
    c.points.emplace_back(1.0 + i, 2.0, 0.5);
    c.times_ns.push_back(c.stamp_ns + i * 1000);
  }
  TimeConvention t;
  t.field = "t";
  const auto m = EncodePointCloud2(
      c,
      {{"x", kFloat32, 0, 1}, {"y", kFloat32, 4, 1}, {"z", kFloat32, 8, 1}, {"t", kUInt32, 12, 1}},
      16, t, "os1_lidar");
  bag.write("/os1_cloud_node/points", m.header.stamp, m);
}

TEST(BagExtrinsicOrigin, PresetChosenOverATfTreeThatDoesNotConnectTheFramesIsAGuess) {
  const fs::path d = testing::FreshTempDir("extrinsic_origin");
  {
    WriteBag((d / "guess.bag").string(), "base_link", "os1_sensor");
    WarningSink sink;
    RosbagSource s((d / "guess.bag").string());
    EXPECT_THAT(s.ExtrinsicOrigin(),
                HasSubstr("the newer_college_2020 preset (recognised from the topic names) — a "
                          "guess: the bag's /tf_static does not connect the IMU frame 'os1_imu' "
                          "and the lidar frame 'os1_lidar'"));
    EXPECT_THAT(sink.text(), HasSubstr("guess.bag: T_imu_lidar from the newer_college_2020"));
    EXPECT_TRUE(s.ImuFromLidar().Matrix().isApprox(NewerCollegeImuFromLidar().Matrix()));
  }
  {
    WriteBag((d / "tf.bag").string(), "os1_imu", "os1_lidar");
    WarningSink sink;
    RosbagSource s((d / "tf.bag").string());
    EXPECT_EQ(s.ExtrinsicOrigin(), "the bag's /tf_static (os1_imu → os1_lidar)");
    EXPECT_THAT(sink.text(), ::testing::Not(HasSubstr("guess")));
    EXPECT_NEAR(s.ImuFromLidar().translation().x(), 0.2, 1e-12);
  }
}

}  // namespace
}  // namespace ctlio::io
