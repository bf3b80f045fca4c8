// ROS 1 bags written with librosbag: the messages of bag_writer.h into rosbag::Bag.
#include <ros/exception.h>
#include <rosbag/bag.h>

#include <stdexcept>
#include <string>

#include "ctlio/io/bag_writer.h"
#include "ctlio/io/livox_custom_msg.h"

namespace ctlio::io {
namespace {

class Ros1Sink : public BagMessageSink {
 public:
  explicit Ros1Sink(rosbag::Bag* bag) : bag_(bag) {}
  void Write(const std::string& topic, int64_t t, const tf2_msgs::TFMessage& m) override {
    bag_->write(topic, Time(t), m);
  }
  void Write(const std::string& topic, int64_t t, const sensor_msgs::Imu& m) override {
    bag_->write(topic, Time(t), m);
  }
  void Write(const std::string& topic, int64_t t, const sensor_msgs::PointCloud2& m) override {
    bag_->write(topic, Time(t), m);
  }
  void Write(const std::string& topic, int64_t t, const nav_msgs::Odometry& m) override {
    bag_->write(topic, Time(t), m);
  }
  void Write(const std::string& topic, int64_t t, const livox::CustomMsg& m) override {
    bag_->write(topic, Time(t), m);
  }

 private:
  static ros::Time Time(int64_t ns) {
    // ros::TIME_MIN is 1 ns: a bag cannot hold time 0 (the simulator's default start).
    if (ns < 1) {
      throw std::runtime_error(
          "time " + std::to_string(ns) +
          " ns: a ROS 1 bag holds times from 1 ns on (start the sequence later)");
    }
    ros::Time t;
    t.fromNSec(uint64_t(ns));
    return t;
  }
  rosbag::Bag* bag_;
};

}  // namespace

size_t WriteRosbag(DataSource& source, const std::string& path, const RosbagWriteOptions& options,
                   const std::function<void(size_t, size_t)>& progress) {
  RequireFirstImuInBodyFrame(source, path + " (ROS bag)");
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    if (options.compression == "lz4") {
      bag.setCompression(rosbag::compression::LZ4);
    } else if (options.compression == "bz2") {
      bag.setCompression(rosbag::compression::BZ2);
    } else if (options.compression != "none") {
      throw std::runtime_error(path + ": unknown bag compression '" + options.compression +
                               "' (none, lz4, bz2)");
    }
    Ros1Sink sink(&bag);
    const size_t n = WriteBagMessages(source, sink, options, progress);
    bag.close();
    return n;
  } catch (const ros::Exception& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::string& topic, const std::string& frame,
                      const std::string& child_frame) {
  WriteOdometryBag(path, trajectory, std::vector<std::array<double, 36>>(trajectory.size()), topic,
                   frame, child_frame);
}

void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::vector<std::array<double, 36>>& pose_covariances,
                      const std::string& topic, const std::string& frame,
                      const std::string& child_frame) {
  if (pose_covariances.size() != trajectory.size()) {
    throw std::invalid_argument(path + ": " + std::to_string(pose_covariances.size()) +
                                " pose covariances for " + std::to_string(trajectory.size()) +
                                " poses");
  }
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    Ros1Sink sink(&bag);
    WriteOdometryMessages(trajectory, pose_covariances, topic, frame, child_frame, sink);
    bag.close();
  } catch (const ros::Exception& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

}  // namespace ctlio::io
