// BagSource's state, shared by its files: bag_source.cc (opening: topics, extrinsic, ground
// truth; Next), bag_scan.cc (a PointCloud2 into a ScanFrame), bag_imu.cc (an Imu into the IMU
// stream), bag_tf_static.cc (the extrinsic from /tf_static).
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {

struct BagSource::Impl {
  std::string path;
  BagOptions options;
  const BagPreset* preset = nullptr;
  std::unique_ptr<BagStream> stream;
  bool exhausted = false;
  std::string lidar_topic, imu_topic, lidar_frame, imu_frame;
  bool custom_msg = false;  // the lidar topic is livox_ros_driver2/CustomMsg (livox_custom_msg.h)
  size_t num_scans = 0, lidar_messages = 0, imu_messages = 0, next_index = 0;
  std::deque<ScanFrame> pending;
  std::vector<ImuSample> imu;  // samples not yet handed out
  int64_t last_imu_ns = INT64_MIN, last_scan_start_ns = INT64_MIN;
  size_t duplicates = 0;
  size_t unusable_scans = 0;        // handed on empty or with their nominal interval (AddScan)
  size_t retimed_scans = 0;         // per-point times rescaled or replaced (point_time_check.h)
  size_t points_outside_sweep = 0;  // dropped: timed over a period from the stamp
  // Header stamps of the lidar messages: the last one and the last spacing (the scan period as
  // the bag shows it, for the nominal interval of an unusable scan).
  int64_t last_lidar_stamp_ns = INT64_MIN, last_lidar_spacing_ns = 0;
  uint64_t bytes = 0;
  double accel_norm_sum = 0.0;
  bool azimuth_logged = false;
  SE3 extrinsic;
  std::string extrinsic_origin;  // empty: unknown
  std::vector<StampedPose> ground_truth;
  // Repeated warnings (IMU gaps, unusable scans): the first few in full, then a total at the end.
  std::unique_ptr<WarningLimiter> warnings;

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path + ": " + what);
  }
  std::string Where(const std::string& topic, size_t n) const {
    return path + ": topic " + topic + ", message " + std::to_string(n) + ": ";
  }
  void Open();
  void ChooseExtrinsic();  // bag_tf_static.cc
  void ReadGroundTruth();
  void ReadOne();
  void AddImu(const sensor_msgs::Imu& m);           // bag_imu.cc
  void AddScan(const sensor_msgs::PointCloud2& m);  // bag_scan.cc
  void LogTotals();                                 // bag_imu.cc
};

}  // namespace ctlio::io
