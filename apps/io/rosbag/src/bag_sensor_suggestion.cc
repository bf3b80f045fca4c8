#include "ctlio/io/bag_sensor_suggestion.h"

#include <glog/logging.h>

#include <memory>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {

std::optional<SensorSuggestion> SuggestSensorConfigForBag(const std::string& path,
                                                          const std::string& lidar_topic) {
  try {
    std::unique_ptr<BagStream> stream =
        IsRos2BagPath(path) ? OpenRos2BagStream(path) : OpenRos1BagStream(path);
    const auto topics = stream->Topics();
    const auto it = topics.find(lidar_topic);
    if (it == topics.end()) return std::nullopt;
    stream->Select({lidar_topic});
    if (!stream->Next()) return std::nullopt;
    RecordingTraits traits;
    traits.lidar_topic = lidar_topic;
    traits.lidar_type = it->second;  // ROS 1 type names in both bag kinds (bag_stream.h)
    const bool custom = traits.lidar_type == livox::kCustomMsgType;
    const sensor_msgs::PointCloud2 msg = livox::ReadLidarMessage(*stream, custom, "");
    PointLayout layout;
    PointCloud cloud = DecodePointCloud2(msg, {}, "", &layout);
    traits.time_driver = layout.time ? layout.convention.driver : "";
    if (custom) cloud.ring.clear();  // lines, not rings
    MeasureScan(cloud, &traits);
    return SuggestSensorConfig(traits);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void LogSensorSuggestion(const DataSource& source) {
  const auto* bag = dynamic_cast<const BagSource*>(&source);
  if (!bag) return;
  // BagSource::Name() is "<kind>:<path>", the kind "rosbag" or "ros2bag" (bag_stream.h).
  const std::string name = bag->Name();
  const size_t colon = name.find(':');
  if (colon == std::string::npos) return;
  if (const auto s = SuggestSensorConfigForBag(name.substr(colon + 1), bag->lidar_topic())) {
    LOG(INFO) << "no --config: this recording looks like sensor " << s->sensor << " ("
              << s->evidence << "); try --config " << s->config
              << (s->note.empty() ? "" : "; " + s->note);
  }
}

}  // namespace ctlio::io
