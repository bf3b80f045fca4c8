// ROS 2 bags: the messages of bag_writer.h in CDR (cdr_messages.h) into a container writer.
#include <map>
#include <stdexcept>

#include "ctlio/io/bag_writer.h"
#include "ctlio/io/cdr_livox.h"
#include "ctlio/io/cdr_messages.h"

namespace ctlio::io {
namespace {

class Ros2Sink : public BagMessageSink {
 public:
  explicit Ros2Sink(Ros2ContainerWriter* writer) : writer_(writer) {}
  void Write(const std::string& topic, int64_t t, const tf2_msgs::TFMessage& m) override {
    Put(topic, "tf2_msgs/msg/TFMessage", t, ros2::EncodeCdr(m));
  }
  void Write(const std::string& topic, int64_t t, const sensor_msgs::Imu& m) override {
    Put(topic, "sensor_msgs/msg/Imu", t, ros2::EncodeCdr(m));
  }
  void Write(const std::string& topic, int64_t t, const sensor_msgs::PointCloud2& m) override {
    Put(topic, "sensor_msgs/msg/PointCloud2", t, ros2::EncodeCdr(m));
  }
  void Write(const std::string& topic, int64_t t, const livox::CustomMsg& m) override {
    Put(topic, "livox_ros_driver2/msg/CustomMsg", t, ros2::EncodeCdr(m));
  }
  void Write(const std::string& topic, int64_t t, const nav_msgs::Odometry& m) override {
    Put(topic, "nav_msgs/msg/Odometry", t, ros2::EncodeCdr(m));
  }

 private:
  void Put(const std::string& topic, const std::string& type, int64_t t,
           const std::vector<uint8_t>& data) {
    auto it = topics_.find(topic);
    if (it == topics_.end()) it = topics_.emplace(topic, writer_->AddTopic(topic, type)).first;
    writer_->Write(it->second, t, data);
  }
  Ros2ContainerWriter* writer_;
  std::map<std::string, size_t> topics_;
};

}  // namespace

ros2::Ros2Compression ParseRos2Compression(const std::string& name) {
  if (name == "none") return ros2::Ros2Compression::kNone;
  if (name == "zstd") return ros2::Ros2Compression::kZstd;
  if (name == "lz4") return ros2::Ros2Compression::kLz4;
  throw std::runtime_error("unknown ROS 2 bag compression '" + name + "' (none, zstd, lz4)");
}

size_t WriteRos2Bag(DataSource& source, Ros2ContainerWriter& writer,
                    const RosbagWriteOptions& options,
                    const std::function<void(size_t, size_t)>& progress) {
  Ros2Sink sink(&writer);
  const size_t n = WriteBagMessages(source, sink, options, progress);
  writer.Close();
  return n;
}

size_t WriteRos2Bag(DataSource& source, const std::string& path, const RosbagWriteOptions& options,
                    const Ros2WriteOptions& ros2,
                    const std::function<void(size_t, size_t)>& progress) {
  RequireFirstImuInBodyFrame(source, path + " (ROS 2 bag)");
  const auto writer = OpenRos2ContainerWriter(path, ros2.storage, ros2.compression);
  try {
    return WriteRos2Bag(source, *writer, options, progress);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

void WriteOdometryRos2Bag(const std::string& path, const std::vector<StampedPose>& trajectory,
                          const std::vector<std::array<double, 36>>& pose_covariances,
                          const std::string& topic, const std::string& frame,
                          const std::string& child_frame) {
  const auto writer =
      OpenRos2ContainerWriter(path, ros2::Ros2Storage::kMcap, ros2::Ros2Compression::kNone);
  Ros2Sink sink(writer.get());
  WriteOdometryMessages(trajectory, pose_covariances, topic, frame, child_frame, sink);
  writer->Close();
}

std::pair<std::string, std::string> WriteEstimateBag(
    const std::string& out_dir, const std::string& source_name,
    const std::vector<StampedPose>& trajectory,
    const std::vector<std::array<double, 36>>& pose_covariances) {
  if (source_name.rfind("ros2bag:", 0) == 0) {
    WriteOdometryRos2Bag(out_dir + "/trajectory_bag", trajectory, pose_covariances);
    return {out_dir + "/trajectory_bag", "the estimate as nav_msgs/Odometry (ROS 2 bag, MCAP)"};
  }
  WriteOdometryBag(out_dir + "/trajectory.bag", trajectory, pose_covariances);
  return {out_dir + "/trajectory.bag", "the estimate as nav_msgs/Odometry (ROS 1 bag)"};
}

}  // namespace ctlio::io
