// The ROS 2 backend of BagSource (bag_stream.h) with the container in memory: the simulator
// written by WriteRos2Bag (CDR through cdr_messages.h) is read back frame by frame exactly as the
// same simulator written as a ROS 1 bag (points, per-point times, IMU, extrinsic, ground truth),
// in either CDR byte order; and the ROS 2 bad inputs name the bag, topic and message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "ctlio/io/bag_writer.h"
#include "ctlio/io/cdr_messages.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "io/ros2_memory_bag.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::ctlio::testing::ExpectError;
using ros2_test::MemoryBag;
using ros2_test::Read;
using ros2_test::ReadAll;
using ros2_test::SmallBag;
using ros2_test::SmallSim;
using ros2_test::TopicIndex;
using ::testing::HasSubstr;

// Every message decoded and encoded again big-endian: the same bag in the other byte order.
MemoryBag BigEndian(const MemoryBag& bag) {
  MemoryBag out = bag;
  for (ros2::Ros2Message& m : out.messages) {
    const std::string type = bag.topics[m.topic].type;
    auto again = [&](auto msg) {
      ros2::DecodeCdr(m.data.data(), m.data.size(), "", &msg);
      m.data = ros2::EncodeCdr(msg, ros2::CdrEndian::kBig);
    };
    if (type == "sensor_msgs/msg/PointCloud2") again(sensor_msgs::PointCloud2());
    if (type == "sensor_msgs/msg/Imu") again(sensor_msgs::Imu());
    if (type == "tf2_msgs/msg/TFMessage") again(tf2_msgs::TFMessage());
    if (type == "nav_msgs/msg/Odometry") again(nav_msgs::Odometry());
    EXPECT_EQ(m.data[1], 0);  // CDR_BE
  }
  return out;
}

TEST(Ros2BagSource, GivesTheSameFramesAsTheRos1BagOfTheSameSequence) {
  const fs::path d = testing::FreshTempDir("ros2_bag_source");
  const std::string ros1 = (d / "sim.bag").string();
  sim::SimulatedSource for_ros1(SmallSim());
  const size_t n = WriteRosbag(for_ros1, ros1);
  RosbagSource ros1_source(ros1);
  const auto expected = ReadAll(ros1_source);
  ASSERT_EQ(expected.size(), n);
  ASSERT_GT(n, 3u);

  MemoryBag bag;
  sim::SimulatedSource for_ros2(SmallSim());
  EXPECT_EQ(WriteRos2Bag(for_ros2, bag), n);
  EXPECT_TRUE(bag.closed);
  ASSERT_EQ(bag.topics.size(), 4u);
  EXPECT_EQ(bag.topics[0].name, "/tf_static");
  EXPECT_EQ(bag.topics[0].type, "tf2_msgs/msg/TFMessage");
  for (const MemoryBag& b : {bag, BigEndian(bag)}) {
    SCOPED_TRACE(b.messages[0].data[1] == 1 ? "CDR_LE" : "CDR_BE");
    const auto read = Read(b);
    EXPECT_EQ(read->Name(), "ros2bag:mem");
    EXPECT_EQ(read->NumScans(), n);
    EXPECT_EQ(read->lidar_topic(), "/os_cloud_node/points");
    EXPECT_EQ(read->ExtrinsicOrigin(), ros1_source.ExtrinsicOrigin());
    EXPECT_THAT(read->ExtrinsicOrigin(), HasSubstr("/tf_static (os_imu → os_lidar)"));
    EXPECT_EQ(read->ImuFromLidar().Matrix(), ros1_source.ImuFromLidar().Matrix());
    const auto frames = ReadAll(*read);
    ASSERT_EQ(frames.size(), expected.size());
    for (size_t k = 0; k < frames.size(); ++k) {
      const ScanFrame &a = frames[k], &e = expected[k];
      EXPECT_EQ(a.index, e.index);
      EXPECT_EQ(a.start_ns, e.start_ns);
      EXPECT_EQ(a.end_ns, e.end_ns);
      EXPECT_EQ(a.cloud.stamp_ns, e.cloud.stamp_ns);
      EXPECT_EQ(a.cloud.points, e.cloud.points) << "scan " << k;
      EXPECT_EQ(a.cloud.times_ns, e.cloud.times_ns) << "scan " << k;
      ASSERT_EQ(a.imu.size(), e.imu.size()) << "scan " << k;
      for (size_t i = 0; i < a.imu.size(); ++i) {
        EXPECT_EQ(a.imu[i].t_ns, e.imu[i].t_ns);
        EXPECT_EQ(a.imu[i].gyro, e.imu[i].gyro);
        EXPECT_EQ(a.imu[i].accel, e.imu[i].accel);
      }
    }
    const auto gt = read->GroundTruth(), gt1 = ros1_source.GroundTruth();
    ASSERT_TRUE(gt && gt1);
    ASSERT_EQ(gt->size(), gt1->size());
    for (size_t i = 0; i < gt->size(); ++i) {
      EXPECT_EQ((*gt)[i].t_ns, (*gt1)[i].t_ns);
      EXPECT_EQ((*gt)[i].pose.Matrix(), (*gt1)[i].pose.Matrix());
    }
    EXPECT_EQ(read->bytes_read() > 0, true);
  }
}

TEST(Ros2BagSource, ACorruptMessageNamesTheBagTopicMessageAndContainerPosition) {
  MemoryBag bag = SmallBag();
  const size_t imu = TopicIndex(bag, "/os_cloud_node/imu");
  size_t seen = 0;
  for (ros2::Ros2Message& m : bag.messages) {
    if (m.topic == imu && ++seen == 5) m.data.resize(m.data.size() - 9);
  }
  const auto read = Read(bag);
  ExpectError([&] { ReadAll(*read); },
              {"mem: topic /os_cloud_node/imu, message 5 [memory: message ",
               "]: corrupt sensor_msgs/msg/Imu message: linear_acceleration_covariance"});
}

// An MCAP file cut short (a recording interrupted) is read up to its last complete record; the
// recovery is an input defect of the run naming the file, and an error under --strict.
TEST(Ros2BagSource, AnMcapFileCutShortIsAnInputDefectAndAnErrorUnderStrict) {
  const fs::path dir = testing::FreshTempDir("ros2_cut_mcap");
  const std::string bag = (dir / "cut").string();
  {
    sim::SimulatedSource s(SmallSim());
    WriteRos2Bag(s, bag);
  }
  std::string mcap;
  for (const auto& e : fs::directory_iterator(bag)) {
    if (e.path().extension() == ".mcap") mcap = e.path().string();
  }
  ASSERT_FALSE(mcap.empty());
  {
    BagSource whole(bag);
    EXPECT_TRUE(whole.InputDefects().empty());
  }
  fs::resize_file(mcap, fs::file_size(mcap) * 6 / 10);
  {
    BagSource cut(bag);
    ReadAll(cut);  // what is left is read without an error (here: less than its one chunk)
    const auto defects = cut.InputDefects();
    ASSERT_EQ(defects.size(), 1u);
    EXPECT_EQ(defects[0].kind, "bag file cut short");
    EXPECT_EQ(defects[0].count, 1u);
    EXPECT_THAT(defects[0].first, HasSubstr(mcap + ": does not end with the MCAP magic"));
  }
  WarningLimiter::SetStrict(true);
  ExpectError([&] { BagSource strict(bag); }, {mcap, "bag file cut short", "--strict"});
  WarningLimiter::SetStrict(false);
}

TEST(Ros2BagSource, TopicsAreChosenAndCheckedWithRos1TypeNames) {
  MemoryBag bag = SmallBag();
  // (Other names than the Newer College 2021 preset's, which would pick its lidar topic.)
  bag.topics[TopicIndex(bag, "/os_cloud_node/points")].name = "/a/points";
  bag.topics.push_back({"/b/points", "sensor_msgs/msg/PointCloud2", "cdr", 0});
  ExpectError([&] { Read(bag); }, {"mem: 2 sensor_msgs/PointCloud2 topics: /a/points /b/points; "
                                   "choose with --lidar_topic"});
  BagOptions o;
  o.lidar_topic = "/os_cloud_node/imu";
  ExpectError([&] { Read(bag, o); },
              {"topic '/os_cloud_node/imu' is sensor_msgs/Imu, not sensor_msgs/PointCloud2"});
  o.lidar_topic = "/a/points";
  EXPECT_EQ(Read(bag, o)->NumScans(), 6u);
  o.lidar_topic = "/b/points";  // listed, but without messages: no scans
  EXPECT_EQ(Read(bag, o)->NumScans(), 0u);
}

TEST(Ros2BagSource, AnotherSerializationOrTypeOnTheTopicIsAnError) {
  MemoryBag bag = SmallBag();
  bag.topics[TopicIndex(bag, "/os_cloud_node/imu")].serialization_format = "ros1";
  ExpectError([&] { Read(bag); },
              {"mem: ", "topic /os_cloud_node/imu is serialized as 'ros1', not cdr"});
  bag = SmallBag();
  bag.topics[TopicIndex(bag, "/ground_truth")].type = "geometry_msgs/msg/PoseStamped";
  ExpectError([&] { Read(bag); }, {"mem: topic /ground_truth, message 1 [memory: message ",
                                   "corrupt geometry_msgs/msg/PoseStamped message"});
}

TEST(Ros2BagSource, GroundTruthFromPoseStamped) {
  MemoryBag bag = SmallBag();
  const size_t gt = TopicIndex(bag, "/ground_truth");
  bag.topics[gt].type = "geometry_msgs/msg/PoseStamped";
  std::vector<std::pair<int64_t, SE3>> poses;
  for (ros2::Ros2Message& m : bag.messages) {
    if (m.topic != gt) continue;
    nav_msgs::Odometry o;
    ros2::DecodeCdr(m.data.data(), m.data.size(), "", &o);
    geometry_msgs::PoseStamped p;
    p.header = o.header;
    p.pose = o.pose.pose;
    m.data = ros2::EncodeCdr(p);
  }
  const auto read = Read(bag);
  const auto truth = sim::SimulatedSource(SmallSim()).GroundTruth();
  const auto got = read->GroundTruth();
  ASSERT_TRUE(got && truth);
  ASSERT_EQ(got->size(), truth->size());
  EXPECT_EQ(got->front().t_ns, truth->front().t_ns);
  EXPECT_LT((got->back().pose.Matrix() - truth->back().pose.Matrix()).norm(), 1e-12);
}

}  // namespace
}  // namespace ctlio::io
