// What each lidar driver writes: the per-point fields of its cloud (and its time convention,
// point_fields.h), its topic and frame names, and the unit of its IMU's accelerometer. Writers
// (WriteRosbag) lay a scan out as the sensor's driver does; readers recognise a recording's sensor
// from the same tables (SuggestSensorConfig) to suggest the shipped config
// data/sensors/<name>.yaml.
//
// Drivers (ROS 1 names; the ROS 2 ports keep them):
// * ouster_ros: `t` uint32 ns since the stamp = scan start; /ouster/points, /ouster/imu, frames
//   os_lidar / os_imu (the older os_cloud_node/* names are the Newer College preset's).
// * velodyne_pointcloud (PointXYZIRT, packed 22 bytes): x y z intensity float32, ring uint16,
//   time float32 s since the stamp = scan END (the driver stamps a scan with its last packet);
//   /velodyne_points, frame velodyne. The IMU is external: /imu/data, frame imu_link.
// * HesaiLidar_ROS_2.0 (PointXYZIT, 48 bytes): x y z intensity float32, timestamp float64 absolute
//   s, ring uint16; stamp = scan start; /hesai/pandar, frame hesai_lidar; external IMU as above.
// * livox_ros_driver2, xfer_format 0 (LivoxPointXyzrtlt, packed 26 bytes): x y z intensity float32,
//   tag line uint8, timestamp float64 absolute ns; stamp = the first point's packet time;
//   /livox/lidar, /livox/imu, both in frame livox_frame (no transform between them is published:
//   the extrinsic comes from the config). xfer_format 1 is the CustomMsg (livox_custom_msg.h).
//   The built-in IMU reports acceleration in g (accel_unit 9.80665 m/s² per unit).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/io/point_fields.h"

namespace ctlio::io {

enum class PointFormat { kOuster, kVelodyne, kHesai, kLivoxPointCloud2, kLivoxCustomMsg };
const char* PointFormatName(PointFormat format);  // "ouster", "velodyne", ...

struct DriverConvention {
  std::string driver;  // "ouster_ros", "velodyne_pointcloud", ...
  PointFormat format = PointFormat::kOuster;
  std::string lidar_topic, imu_topic, lidar_frame, imu_frame;
  double accel_unit = 1.0;  // m/s² per unit of the published accelerometer (9.80665: g)
};
// The driver's conventions for `format` (topics and frames as listed above).
DriverConvention DriverConventionOf(PointFormat format);

// The PointCloud2 fields of a format (kLivoxCustomMsg: its conversion to PointCloud2,
// livox_custom_msg.h) and the time convention to encode them with (absolute or relative to the
// stamp; for Velodyne the stamp must be the scan end).
std::vector<PointField> DriverFields(PointFormat format, uint32_t* point_step);
TimeConvention DriverTime(PointFormat format);

}  // namespace ctlio::io
