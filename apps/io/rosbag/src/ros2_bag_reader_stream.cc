// BagStream over a ROS 2 bag on disk: Ros2BagReader (ros2_bag.h) as the ROS 2 backend's
// container.
#include "ctlio/io/bag_stream.h"

namespace ctlio::io {
namespace {

class ReaderContainer : public Ros2Container {
 public:
  explicit ReaderContainer(const std::string& path) : reader_(path) {}
  const std::vector<ros2::Ros2Topic>& topics() const override { return reader_.topics(); }
  void SetTopicFilter(const std::vector<size_t>& topics) override {
    reader_.SetTopicFilter(topics);
  }
  bool Next(ros2::Ros2Message* message) override { return reader_.Next(message); }
  std::string Where() const override { return reader_.Where(); }

 private:
  ros2::Ros2BagReader reader_;
};

}  // namespace

std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path) {
  return OpenRos2BagStream(path, [path] { return std::make_unique<ReaderContainer>(path); });
}

bool IsRos2BagPath(const std::string& path) { return ros2::IsRos2Bag(path); }

}  // namespace ctlio::io
