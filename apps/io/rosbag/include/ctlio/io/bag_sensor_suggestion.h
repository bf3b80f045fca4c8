// The sensor suggestion of sensor_suggestion.h for a bag (ROS 1 or ROS 2): its topics, the lidar
// topic's type and first message (fields and points). Advisory: any error reading the bag gives no
// suggestion (the reader itself reports it).
#pragma once

#include <optional>
#include <string>

#include "ctlio/io/dataset.h"
#include "ctlio/io/sensor_suggestion.h"

namespace ctlio::io {

// `lidar_topic`: the topic the reader chose (RosbagSource::lidar_topic()).
std::optional<SensorSuggestion> SuggestSensorConfigForBag(const std::string& path,
                                                          const std::string& lidar_topic);

// Logs the suggestion (INFO) when `source` is a bag (BagSource) whose recording gives its sensor
// away; ctlio_odometry calls it when no --config is given.
void LogSensorSuggestion(const DataSource& source);

}  // namespace ctlio::io
