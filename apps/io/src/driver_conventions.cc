#include "ctlio/io/driver_conventions.h"

#include <stdexcept>

namespace ctlio::io {

const char* PointFormatName(PointFormat format) {
  switch (format) {
    case PointFormat::kOuster:
      return "ouster";
    case PointFormat::kVelodyne:
      return "velodyne";
    case PointFormat::kHesai:
      return "hesai";
    case PointFormat::kLivoxPointCloud2:
      return "livox_pointcloud2";
    case PointFormat::kLivoxCustomMsg:
      return "livox_custom";
  }
  return "?";
}

DriverConvention DriverConventionOf(PointFormat format) {
  DriverConvention d;
  d.format = format;
  switch (format) {
    case PointFormat::kOuster:
      d = {"ouster_ros", format, "/ouster/points", "/ouster/imu", "os_lidar", "os_imu", 1.0};
      break;
    case PointFormat::kVelodyne:
      d = {"velodyne_pointcloud",
           format,
           "/velodyne_points",
           "/imu/data",
           "velodyne",
           "imu_link",
           1.0};
      break;
    case PointFormat::kHesai:
      d = {"HesaiLidar_ROS_2.0", format, "/hesai/pandar", "/imu/data", "hesai_lidar",
           "imu_link",           1.0};
      break;
    case PointFormat::kLivoxPointCloud2:
    case PointFormat::kLivoxCustomMsg:
      d = {"livox_ros_driver2", format,        "/livox/lidar", "/livox/imu",
           "livox_frame",       "livox_frame", 9.80665};
      break;
  }
  return d;
}

std::vector<PointField> DriverFields(PointFormat format, uint32_t* point_step) {
  switch (format) {
    case PointFormat::kOuster:
      return OusterFields(point_step);
    case PointFormat::kVelodyne:
      *point_step = 22;
      return {{"x", kFloat32, 0, 1},          {"y", kFloat32, 4, 1},    {"z", kFloat32, 8, 1},
              {"intensity", kFloat32, 12, 1}, {"ring", kUInt16, 16, 1}, {"time", kFloat32, 18, 1}};
    case PointFormat::kHesai:
      *point_step = 48;
      return {{"x", kFloat32, 0, 1},          {"y", kFloat32, 4, 1},
              {"z", kFloat32, 8, 1},          {"intensity", kFloat32, 16, 1},
              {"timestamp", kFloat64, 24, 1}, {"ring", kUInt16, 32, 1}};
    case PointFormat::kLivoxPointCloud2:
      *point_step = 26;
      return {{"x", kFloat32, 0, 1},          {"y", kFloat32, 4, 1},  {"z", kFloat32, 8, 1},
              {"intensity", kFloat32, 12, 1}, {"tag", kUInt8, 16, 1}, {"line", kUInt8, 17, 1},
              {"timestamp", kFloat64, 18, 1}};
    case PointFormat::kLivoxCustomMsg:
      // The CustomPoint fields as a PointCloud2 (livox_custom_msg.h): offset_time first.
      *point_step = 19;
      return {{"offset_time", kUInt32, 0, 1}, {"x", kFloat32, 4, 1},        {"y", kFloat32, 8, 1},
              {"z", kFloat32, 12, 1},         {"intensity", kUInt8, 16, 1}, {"tag", kUInt8, 17, 1},
              {"line", kUInt8, 18, 1}};
  }
  throw std::logic_error("DriverFields: unknown format");
}

TimeConvention DriverTime(PointFormat format) {
  TimeConvention c;
  switch (format) {
    case PointFormat::kOuster:
      c.field = "t";
      c.driver = "Ouster";
      break;
    case PointFormat::kVelodyne:
      c.field = "time";
      c.unit = TimeUnit::kSeconds;
      c.stamp_at = StampAt::kScanEnd;
      c.driver = "Velodyne";
      break;
    case PointFormat::kHesai:
      c.field = "timestamp";
      c.unit = TimeUnit::kSeconds;
      c.reference = TimeReference::kAbsolute;
      c.driver = "Hesai/Robosense";
      break;
    case PointFormat::kLivoxPointCloud2:
      c.field = "timestamp";
      c.reference = TimeReference::kAbsolute;
      c.driver = "Livox driver 2";
      break;
    case PointFormat::kLivoxCustomMsg:
      c.field = "offset_time";
      c.driver = "Livox CustomPoint";
      break;
  }
  return c;
}

}  // namespace ctlio::io
