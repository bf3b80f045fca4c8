// The messages of a bag as BagSource (rosbag_source.h) reads them, whatever the container: one
// small interface with a ROS 1 backend (rosbag::View over Debian's librosbag) and a ROS 2 backend
// (a ROS 2 container, ros2_bag.h, with the CDR decoders of cdr_messages.h). Both hand out the ROS 1
// C++ message structs, so topic selection, the extrinsic, scan assembly and every check of the
// bad-input work are one code for both. Type names are ROS 1's ("sensor_msgs/PointCloud2"); a
// ROS 2 bag's "sensor_msgs/msg/PointCloud2" is mapped.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/livox_msgs.h"
#include "ctlio/io/ros2_bag.h"

namespace ctlio::io {

class BagStream {
 public:
  virtual ~BagStream() = default;
  // "rosbag" or "ros2bag" (DataSource::Name's prefix).
  virtual std::string Kind() const = 0;
  // Topic name → ROS 1 type name.
  virtual std::map<std::string, std::string> Topics() const = 0;
  // Messages on `topic`; 0 when the container does not say.
  virtual size_t MessageCount(const std::string& topic) = 0;
  // Starts a pass from the bag's start over the messages of `topics`, in receive-time order.
  virtual void Select(const std::vector<std::string>& topics) = 0;
  // Advances the pass to its next message; false at its end.
  virtual bool Next() = 0;
  // The current message: its topic, whether it is of the ROS 1 type `type`, and its size.
  virtual const std::string& topic() const = 0;
  virtual bool Holds(const std::string& type) const = 0;
  virtual uint64_t size() const = 0;
  // The current message decoded; errors are std::runtime_error prefixed by `where` (bag, topic,
  // message number): a message of another type, a corrupt message.
  virtual void Read(const std::string& where, sensor_msgs::PointCloud2* msg) = 0;
  virtual void Read(const std::string& where, sensor_msgs::Imu* msg) = 0;
  virtual void Read(const std::string& where, tf2_msgs::TFMessage* msg) = 0;
  virtual void Read(const std::string& where, nav_msgs::Odometry* msg) = 0;
  virtual void Read(const std::string& where, geometry_msgs::PoseStamped* msg) = 0;
  virtual void Read(const std::string& where, livox::CustomMsg* msg) = 0;
  // What the container recovered from when it was opened (a file cut short), one line each.
  virtual std::vector<std::string> Recovered() const { return {}; }
};

// A ROS 1 bag file (checked by CheckBagStructure first). Throws naming `path`.
std::unique_ptr<BagStream> OpenRos1BagStream(const std::string& path);

// What the ROS 2 backend needs of a container: Ros2BagReader's reading interface (ros2_bag.h),
// so that tests can hand it messages from memory.
class Ros2Container {
 public:
  virtual ~Ros2Container() = default;
  virtual const std::vector<ros2::Ros2Topic>& topics() const = 0;
  virtual void SetTopicFilter(const std::vector<size_t>& topics) = 0;
  virtual bool Next(ros2::Ros2Message* message) = 0;
  virtual std::string Where() const = 0;
  virtual std::vector<std::string> Recovered() const { return {}; }
};
// Opens the container at its first message (called once for the topics and once per pass).
using Ros2ContainerOpener = std::function<std::unique_ptr<Ros2Container>()>;

// A ROS 2 bag whose messages come from `open`; `path` names it in errors.
std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path, Ros2ContainerOpener open);
// A ROS 2 bag folder, .mcap or .db3 file through Ros2BagReader.
std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path);
// True if `path` is a ROS 2 bag (ros2::IsRos2Bag).
bool IsRos2BagPath(const std::string& path);

}  // namespace ctlio::io
