// A ROS 2 bag in memory for the tests of the ROS 2 backend of BagSource (bag_stream.h): what
// Ros2BagWriter would store, read back through the same stream as a bag folder, without files.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/bag_writer.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::io::ros2_test {

inline sim::SimConfig SmallSim() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 1);
  c.duration_s = 0.6;
  c.lidar.beams = 8;
  c.lidar.firing_decimation = 30;
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  return c;
}

// A ROS 2 bag in memory: what Ros2BagWriter would store, read back in log-time order (ties:
// write order), as ros2_bag.h promises of Ros2BagReader.
struct MemoryBag : Ros2ContainerWriter {
  std::vector<ros2::Ros2Topic> topics;
  std::vector<ros2::Ros2Message> messages;
  bool closed = false;
  size_t AddTopic(const std::string& name, const std::string& type) override {
    topics.push_back({name, type, "cdr", 0});
    return topics.size() - 1;
  }
  void Write(size_t topic, int64_t t, const std::vector<uint8_t>& data) override {
    messages.push_back({topic, t, data});
    ++topics[topic].message_count;
  }
  void Close() override {
    std::stable_sort(messages.begin(), messages.end(),
                     [](const auto& a, const auto& b) { return a.log_time_ns < b.log_time_ns; });
    closed = true;
  }
};

class MemoryReader : public Ros2Container {
 public:
  explicit MemoryReader(const MemoryBag* bag) : bag_(bag) {}
  const std::vector<ros2::Ros2Topic>& topics() const override { return bag_->topics; }
  void SetTopicFilter(const std::vector<size_t>& topics) override { filter_ = topics; }
  bool Next(ros2::Ros2Message* m) override {
    while (next_ < bag_->messages.size()) {
      const ros2::Ros2Message& c = bag_->messages[next_++];
      if (filter_.empty() || std::count(filter_.begin(), filter_.end(), c.topic)) {
        *m = c;
        return true;
      }
    }
    return false;
  }
  std::string Where() const override { return "memory: message " + std::to_string(next_); }

 private:
  const MemoryBag* bag_;
  std::vector<size_t> filter_;
  size_t next_ = 0;
};

inline std::unique_ptr<BagSource> Read(const MemoryBag& bag, const BagOptions& options = {}) {
  return std::make_unique<BagSource>(
      "mem", OpenRos2BagStream("mem", [&bag] { return std::make_unique<MemoryReader>(&bag); }),
      options);
}

inline std::vector<ScanFrame> ReadAll(DataSource& s) {
  std::vector<ScanFrame> out;
  ScanFrame f;
  while (s.Next(&f)) out.push_back(f);
  return out;
}

inline MemoryBag SmallBag() {
  MemoryBag bag;
  sim::SimulatedSource s(SmallSim());
  WriteRos2Bag(s, bag);
  return bag;
}

inline size_t TopicIndex(const MemoryBag& bag, const std::string& name) {
  for (size_t i = 0; i < bag.topics.size(); ++i) {
    if (bag.topics[i].name == name) return i;
  }
  return SIZE_MAX;
}

}  // namespace ctlio::io::ros2_test
