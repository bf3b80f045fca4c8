// The ROS 2 backend of BagStream: a container (ros2_bag.h) gives serialized messages, the CDR
// decoders (cdr_messages.h) turn them into the ROS 1 structs the source reads.
#include <ros/message_traits.h>

#include <stdexcept>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/cdr_livox.h"
#include "ctlio/io/cdr_messages.h"
#include "ctlio/io/livox_custom_msg.h"

namespace ctlio::io {
namespace {

class Ros2BagStream : public BagStream {
 public:
  Ros2BagStream(const std::string& path, Ros2ContainerOpener open)
      : path_(path),
        open_(std::move(open)),
        container_(open_()),
        recovered_(container_->Recovered()) {
    for (const ros2::Ros2Topic& t : container_->topics()) {
      topics_.emplace(t.name, ros2::Ros1TypeName(t.type));  // the first type a name has
    }
  }

  std::string Kind() const override { return "ros2bag"; }
  // The first opening's (every pass opens the same files again).
  std::vector<std::string> Recovered() const override { return recovered_; }
  std::map<std::string, std::string> Topics() const override { return topics_; }
  size_t MessageCount(const std::string& topic) override {
    size_t n = 0;
    for (const ros2::Ros2Topic& t : container_->topics()) {
      if (t.name != topic) continue;
      if (t.message_count == 0) return 0;  // unknown
      n += t.message_count;
    }
    return n;
  }
  void Select(const std::vector<std::string>& topics) override {
    // A pass starts from the bag's start: a container reads forward only, so a fresh one.
    if (started_) container_ = open_();
    started_ = true;
    std::vector<size_t> filter;
    const auto& all = container_->topics();
    for (size_t i = 0; i < all.size(); ++i) {
      for (const std::string& name : topics) {
        if (all[i].name == name) filter.push_back(i);
      }
    }
    container_->SetTopicFilter(filter);
    message_ = {};
    // An empty filter would mean every topic: no topic of these names gives no message.
    empty_ = filter.empty();
  }
  bool Next() override {
    if (empty_ || !container_->Next(&message_)) return false;
    if (message_.topic >= container_->topics().size()) {
      throw std::runtime_error(container_->Where() + ": topic index " +
                               std::to_string(message_.topic) + " out of range");
    }
    return true;
  }
  const std::string& topic() const override { return Current().name; }
  bool Holds(const std::string& type) const override {
    return ros2::Ros1TypeName(Current().type) == type;
  }
  uint64_t size() const override { return message_.data.size(); }
  void Read(const std::string& where, sensor_msgs::PointCloud2* m) override { Decode(where, m); }
  void Read(const std::string& where, sensor_msgs::Imu* m) override { Decode(where, m); }
  void Read(const std::string& where, tf2_msgs::TFMessage* m) override { Decode(where, m); }
  void Read(const std::string& where, nav_msgs::Odometry* m) override { Decode(where, m); }
  void Read(const std::string& where, geometry_msgs::PoseStamped* m) override { Decode(where, m); }
  void Read(const std::string& where, livox::CustomMsg* m) override { Decode(where, m); }

 private:
  const ros2::Ros2Topic& Current() const { return container_->topics().at(message_.topic); }

  template <class M>
  void Decode(const std::string& where, M* m) {
    const ros2::Ros2Topic& t = Current();
    const std::string type = ros::message_traits::datatype<M>();
    if (!Holds(type)) {
      throw std::runtime_error(where + "message on " + t.name + " is not a " +
                               ros2::Ros2TypeName(type) + " (type " + t.type + ")");
    }
    if (t.serialization_format != "cdr") {
      throw std::runtime_error(where + "topic " + t.name + " is serialized as '" +
                               t.serialization_format + "', not cdr");
    }
    // The container's position (file, chunk) after the bag's message number.
    const std::string at = where.size() >= 2 ? where.substr(0, where.size() - 2) : where;
    ros2::DecodeCdr(message_.data.data(), message_.data.size(),
                    at + " [" + container_->Where() + "]: ", m);
  }

  std::string path_;
  Ros2ContainerOpener open_;
  std::unique_ptr<Ros2Container> container_;
  std::vector<std::string> recovered_;
  std::map<std::string, std::string> topics_;
  ros2::Ros2Message message_;
  bool started_ = false, empty_ = false;
};

}  // namespace

std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path, Ros2ContainerOpener open) {
  return std::make_unique<Ros2BagStream>(path, std::move(open));
}

}  // namespace ctlio::io
