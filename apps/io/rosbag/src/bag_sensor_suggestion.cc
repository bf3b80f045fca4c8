#include "ctlio/io/bag_sensor_suggestion.h"

#include <glog/logging.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {

std::optional<SensorSuggestion> SuggestSensorConfigForBag(const std::string& path,
                                                          const std::string& lidar_topic) {
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag, rosbag::TopicQuery(lidar_topic));
    if (view.begin() == view.end()) return std::nullopt;
    RecordingTraits traits;
    traits.lidar_topic = lidar_topic;
    traits.lidar_type = view.begin()->getDataType();
    const bool custom = traits.lidar_type == livox::kCustomMsgType;
    const sensor_msgs::PointCloud2 msg = livox::ReadLidarMessage(*view.begin(), custom, "");
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
  const auto* bag = dynamic_cast<const RosbagSource*>(&source);
  const std::string prefix = "rosbag:";  // RosbagSource::Name() is "rosbag:<path>"
  if (!bag || bag->Name().rfind(prefix, 0) != 0) return;
  if (const auto s =
          SuggestSensorConfigForBag(bag->Name().substr(prefix.size()), bag->lidar_topic())) {
    LOG(INFO) << "no --config: this recording looks like sensor " << s->sensor << " ("
              << s->evidence << "); try --config " << s->config
              << (s->note.empty() ? "" : "; " + s->note);
  }
}

}  // namespace ctlio::io
