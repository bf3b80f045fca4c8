#include "ctlio/io/sensor_suggestion.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace ctlio::io {
namespace {

bool Contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

void MeasureScan(const PointCloud& cloud, RecordingTraits* t) {
  t->rings = 0;
  for (uint16_t r : cloud.ring) t->rings = std::max(t->rings, int(r) + 1);
  std::vector<double> az;
  double lo = 90.0, hi = -90.0;
  for (const Vec3& p : cloud.points) {
    const double n = p.norm();
    if (!(n > 0.0)) continue;
    const double el = std::asin(std::clamp(p.z() / n, -1.0, 1.0)) * 180.0 / M_PI;
    lo = std::min(lo, el);
    hi = std::max(hi, el);
    az.push_back(std::atan2(p.y(), p.x()) * 180.0 / M_PI);
  }
  if (az.empty()) {
    t->elevation_span_deg = t->azimuth_span_deg = 0.0;
    return;
  }
  t->elevation_span_deg = hi - lo;
  std::sort(az.begin(), az.end());
  double widest_gap = az.front() + 360.0 - az.back();
  for (size_t i = 1; i < az.size(); ++i) widest_gap = std::max(widest_gap, az[i] - az[i - 1]);
  t->azimuth_span_deg = 360.0 - widest_gap;
}

std::optional<SensorSuggestion> SuggestSensorConfig(const RecordingTraits& t) {
  std::ostringstream why;
  why << "topic " << t.lidar_topic << " (" << t.lidar_type << ")";
  if (!t.time_driver.empty()) why << ", " << t.time_driver << " per-point time";
  why << ", " << t.rings << " rings, " << std::lround(t.elevation_span_deg) << "° × "
      << std::lround(t.azimuth_span_deg) << "° in the first scan";
  SensorSuggestion s;
  const std::string& d = t.time_driver;
  if (Contains(t.lidar_type, "livox") || Contains(d, "Livox") || Contains(t.lidar_topic, "livox")) {
    s.sensor = t.azimuth_span_deg < 180.0 ? "avia" : "mid360";
    s.note = "Livox IMUs publish g: the config sets input.accel_scale: 9.80665";
  } else if (d == "Velodyne" || Contains(t.lidar_topic, "velodyne")) {
    s.sensor = t.rings > 0 && t.rings <= 16 ? "vlp16" : "hdl32e";
  } else if (d == "Hesai/Robosense" || Contains(t.lidar_topic, "hesai") ||
             Contains(t.lidar_topic, "pandar")) {
    s.sensor = "pandar_xt32";
  } else if (d == "Ouster" || Contains(t.lidar_topic, "ouster") ||
             Contains(t.lidar_topic, "os_cloud_node")) {
    s.sensor = t.rings > 0 && t.rings <= 64  ? "os1_64"
               : t.elevation_span_deg > 60.0 ? "os0_128"
                                             : "os1_128";
  } else {
    return std::nullopt;
  }
  s.config = "data/sensors/" + s.sensor + ".yaml";
  s.evidence = why.str();
  return s;
}

}  // namespace ctlio::io
