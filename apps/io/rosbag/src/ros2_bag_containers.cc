// The ROS 2 containers on disk (ros2_bag.h) behind the interfaces the ROS 2 bag stream and the
// ROS 2 bag writer use: Ros2BagReader as a Ros2Container, Ros2BagWriter as a Ros2ContainerWriter.
#include "ctlio/io/bag_stream.h"
#include "ctlio/io/bag_writer.h"

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
  std::vector<std::string> Recovered() const override { return reader_.recovered(); }

 private:
  ros2::Ros2BagReader reader_;
};

class WriterContainer : public Ros2ContainerWriter {
 public:
  WriterContainer(const std::string& path, ros2::Ros2Storage storage,
                  ros2::Ros2Compression compression)
      : writer_(path, storage, compression) {}
  size_t AddTopic(const std::string& name, const std::string& type) override {
    return writer_.AddTopic(name, type);
  }
  void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) override {
    writer_.Write(topic, log_time_ns, data);
  }
  void Close() override { writer_.Close(); }

 private:
  ros2::Ros2BagWriter writer_;
};

}  // namespace

std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path) {
  return OpenRos2BagStream(path, [path] { return std::make_unique<ReaderContainer>(path); });
}

bool IsRos2BagPath(const std::string& path) { return ros2::IsRos2Bag(path); }

std::unique_ptr<Ros2ContainerWriter> OpenRos2ContainerWriter(const std::string& path,
                                                             ros2::Ros2Storage storage,
                                                             ros2::Ros2Compression compression) {
  return std::make_unique<WriterContainer>(path, storage, compression);
}

}  // namespace ctlio::io
