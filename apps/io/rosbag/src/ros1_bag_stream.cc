// The ROS 1 backend of BagStream: rosbag::View over Debian's librosbag, behind the bag structure
// check (bag_structure.h) and the wire checks of the messages with arrays (ros_wire_check.h).
#include <ros/exception.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <optional>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/bag_structure.h"
#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/ros_wire_check.h"

namespace ctlio::io {
namespace {

// md5sums of the types ctlio reads: a connection with the type's name but another definition
// is not the type (Holds), as m.isType<M>() says.
template <class M>
std::pair<std::string, std::string> Known() {
  return {ros::message_traits::datatype<M>(), ros::message_traits::md5sum<M>()};
}

class Ros1BagStream : public BagStream {
 public:
  explicit Ros1BagStream(const std::string& path) : path_(path) {
    // The bag library trusts the file's lengths and offsets: check them first.
    CheckBagStructure(path);
    try {
      bag_.open(path, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) topics_[c->topic] = c->datatype;
    } catch (const std::exception& e) {
      throw std::runtime_error(path +
                               ": cannot read the bag (truncated or corrupted?): " + e.what());
    }
  }

  std::string Kind() const override { return "rosbag"; }
  std::map<std::string, std::string> Topics() const override { return topics_; }
  size_t MessageCount(const std::string& topic) override {
    size_t n = 0;
    Guard([&] { n = rosbag::View(bag_, rosbag::TopicQuery(topic)).size(); });
    return n;
  }
  void Select(const std::vector<std::string>& topics) override {
    Guard([&] {
      view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topics));
      started_ = false;
    });
  }
  bool Next() override {
    bool more = false;
    Guard([&] {
      if (!started_) {
        it_ = view_->begin();
        started_ = true;
      } else {
        ++it_;
      }
      more = it_ != view_->end();
      if (more) topic_ = it_->getTopic();
    });
    return more;
  }
  const std::string& topic() const override { return topic_; }
  bool Holds(const std::string& type) const override {
    static const std::map<std::string, std::string> md5 = {
        Known<sensor_msgs::PointCloud2>(), Known<sensor_msgs::Imu>(), Known<tf2_msgs::TFMessage>(),
        Known<nav_msgs::Odometry>(), Known<geometry_msgs::PoseStamped>()};
    const auto it = md5.find(type);
    return it_->getDataType() == type && (it == md5.end() || it_->getMD5Sum() == it->second);
  }
  uint64_t size() const override { return it_->size(); }
  void Read(const std::string& where, sensor_msgs::PointCloud2* m) override {
    ReadAs(where, CheckPointCloud2Wire, m);
  }
  void Read(const std::string& where, sensor_msgs::Imu* m) override { ReadAs(where, nullptr, m); }
  void Read(const std::string& where, tf2_msgs::TFMessage* m) override {
    ReadAs(where, CheckTfMessageWire, m);
  }
  void Read(const std::string& where, nav_msgs::Odometry* m) override { ReadAs(where, nullptr, m); }
  void Read(const std::string& where, geometry_msgs::PoseStamped* m) override {
    ReadAs(where, nullptr, m);
  }
  void Read(const std::string& where, livox::CustomMsg* m) override {
    ReadAs(where, livox::CheckCustomMsgWire, m);
  }

 private:
  // The library's exceptions as ours, naming the bag.
  template <class F>
  void Guard(const F& f) const {
    try {
      f();
    } catch (const ros::Exception& e) {
      throw std::runtime_error(path_ +
                               ": cannot read the bag (truncated or corrupted?): " + e.what());
    }
  }
  template <class M>
  void ReadAs(const std::string& where, void (*check)(const uint8_t*, size_t, const std::string&),
              M* m) {
    try {
      *m = ReadCheckedMessage<M>(*it_, where, check);
    } catch (const ros::Exception& e) {
      throw std::runtime_error(
          where + "cannot read the message (truncated or corrupted bag?): " + e.what());
    }
  }

  std::string path_;
  mutable rosbag::Bag bag_;
  std::map<std::string, std::string> topics_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  bool started_ = false;
  std::string topic_;
};

}  // namespace

std::unique_ptr<BagStream> OpenRos1BagStream(const std::string& path) {
  return std::make_unique<Ros1BagStream>(path);
}

}  // namespace ctlio::io
