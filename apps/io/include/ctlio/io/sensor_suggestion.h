// Which shipped config (data/sensors/<sensor>.yaml) suits a recording, from what its lidar
// driver left in it: the topic names and message type (driver_conventions.h), the per-point time
// convention detected from the fields (point_fields.h) and the first scan's rings and angular
// spread. ctlio_odometry logs the suggestion when it runs a bag without --config.
//
// Rules, in order: a Livox driver (CustomMsg, a Livox time convention or a /livox topic) → avia
// when the first scan spans less than 180° of azimuth, else mid360; Velodyne (`time` field or
// /velodyne topic) → vlp16 up to 16 rings, else hdl32e; Hesai (`timestamp` without Livox's
// tag/line, or a /hesai topic) → pandar_xt32; Ouster (`t` field or an ouster/os_cloud_node
// topic) → os1_64 up to 64 rings, else os0_128 when the elevations span more than 60°, else
// os1_128. Anything else: no suggestion.
#pragma once

#include <optional>
#include <string>

#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {

struct RecordingTraits {
  std::string lidar_topic;
  std::string lidar_type;   // "sensor_msgs/PointCloud2", "livox_ros_driver2/CustomMsg", ...
  std::string time_driver;  // TimeConvention::driver of the detected time field ("" if none)
  int rings = 0;            // max ring + 1 of the first scan (0: no ring field)
  double elevation_span_deg = 0.0, azimuth_span_deg = 0.0;  // of the first scan's points
};

// The first scan's rings and angular spread (azimuth span: 360° minus the widest empty sector).
void MeasureScan(const PointCloud& cloud, RecordingTraits* traits);

struct SensorSuggestion {
  std::string sensor;    // a sensor model name ("vlp16")
  std::string config;    // "data/sensors/vlp16.yaml"
  std::string evidence;  // what gave it away, for the log
  std::string note;      // extra advice (e.g. the Livox accelerometer in g), may be empty
};
std::optional<SensorSuggestion> SuggestSensorConfig(const RecordingTraits& traits);

}  // namespace ctlio::io
