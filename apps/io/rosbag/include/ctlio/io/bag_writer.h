// Writing any DataSource as a bag, ROS 1 (WriteRosbag, rosbag_source.h) or ROS 2 (WriteRos2Bag
// below): one loop (WriteBagMessages) makes the messages — /tf_static, each IMU sample as
// sensor_msgs/Imu, each scan as the options' lidar driver writes it (driver_conventions.h: an
// Ouster-style PointCloud2 by default, or a Livox CustomMsg), ground truth as nav_msgs/Odometry —
// and a sink stores them, in a ROS 1 bag through librosbag or in a ROS 2 bag as CDR
// (cdr_messages.h) through a container writer (ros2_bag.h). The messages are written in receive
// (log) time order, ground truth interleaved, so that a reader streaming the file meets them in
// the order it hands them out.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/livox_msgs.h"
#include "ctlio/io/ros2_bag.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {

// Where the messages go; `log_ns` is the time the message is recorded at (ROS 1 bag time, MCAP
// log_time).
class BagMessageSink {
 public:
  virtual ~BagMessageSink() = default;
  virtual void Write(const std::string& topic, int64_t log_ns, const tf2_msgs::TFMessage& m) = 0;
  virtual void Write(const std::string& topic, int64_t log_ns, const sensor_msgs::Imu& m) = 0;
  virtual void Write(const std::string& topic, int64_t log_ns,
                     const sensor_msgs::PointCloud2& m) = 0;
  virtual void Write(const std::string& topic, int64_t log_ns, const nav_msgs::Odometry& m) = 0;
  virtual void Write(const std::string& topic, int64_t log_ns, const livox::CustomMsg& m) = 0;
};

// The messages of `source` into `sink` (the loop of WriteRosbag and WriteRos2Bag); the number of
// scans.
size_t WriteBagMessages(DataSource& source, BagMessageSink& sink, const RosbagWriteOptions& options,
                        const std::function<void(size_t, size_t)>& progress = {});
// A trajectory as nav_msgs/Odometry messages on `topic` (WriteOdometryBag's messages), each with
// its pose.covariance (ROS row-major 6×6 over [x y z roll pitch yaw]; zeros when
// `pose_covariances` is empty, else one per pose: std::invalid_argument otherwise).
void WriteOdometryMessages(const std::vector<StampedPose>& trajectory,
                           const std::vector<std::array<double, 36>>& pose_covariances,
                           const std::string& topic, const std::string& frame,
                           const std::string& child_frame, BagMessageSink& sink);

// What the ROS 2 sink needs of a container writer: Ros2BagWriter's interface (ros2_bag.h), so that
// tests can keep the messages in memory.
class Ros2ContainerWriter {
 public:
  virtual ~Ros2ContainerWriter() = default;
  virtual size_t AddTopic(const std::string& name, const std::string& type) = 0;
  virtual void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) = 0;
  virtual void Close() = 0;
};
// A Ros2BagWriter (a bag folder at `path`).
std::unique_ptr<Ros2ContainerWriter> OpenRos2ContainerWriter(const std::string& path,
                                                             ros2::Ros2Storage storage,
                                                             ros2::Ros2Compression compression);
// "none" | "zstd" | "lz4"; throws naming the value otherwise.
ros2::Ros2Compression ParseRos2Compression(const std::string& name);

struct Ros2WriteOptions {
  ros2::Ros2Storage storage = ros2::Ros2Storage::kMcap;
  ros2::Ros2Compression compression = ros2::Ros2Compression::kNone;
};

// WriteRosbag's messages as a ROS 2 bag folder `path` (options.compression, ROS 1's, is not
// used). Returns the number of scans.
size_t WriteRos2Bag(DataSource& source, const std::string& path,
                    const RosbagWriteOptions& options = {}, const Ros2WriteOptions& ros2 = {},
                    const std::function<void(size_t, size_t)>& progress = {});
// The same into any container writer (closed at the end).
size_t WriteRos2Bag(DataSource& source, Ros2ContainerWriter& writer,
                    const RosbagWriteOptions& options = {},
                    const std::function<void(size_t, size_t)>& progress = {});
// WriteOdometryBag as a ROS 2 bag folder (MCAP); `pose_covariances` as WriteOdometryMessages.
void WriteOdometryRos2Bag(const std::string& path, const std::vector<StampedPose>& trajectory,
                          const std::vector<std::array<double, 36>>& pose_covariances = {},
                          const std::string& topic = "/ctlio/odometry",
                          const std::string& frame = "map",
                          const std::string& child_frame = "os_lidar");

}  // namespace ctlio::io
