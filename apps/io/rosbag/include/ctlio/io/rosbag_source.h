// ROS bags (sensor_msgs/PointCloud2 + sensor_msgs/Imu) as a DataSource: ROS 1 bags read with
// ROS's own bag library (rosbag::Bag, rosbag::View) and ROS 2 bags (a folder with metadata.yaml,
// a .mcap or a .db3 file: ros2_bag.h, messages in CDR: cdr_messages.h), both through the message
// stream of bag_stream.h, so that everything below is one code for both. Streamed message by
// message: only the bag's index and the scans waiting for their IMU samples are in memory, so a
// bag of tens of GB is fine.
//
// Topics: --lidar_topic / --imu_topic; left empty, the only PointCloud2 and the only Imu topic of
// the bag are used (several candidates: an error listing them). A livox_ros_driver2/CustomMsg
// topic is read as the lidar when named or when the bag has no PointCloud2 (livox_custom_msg.h). A
// dataset preset (Newer College 2020/2021, chosen by name or recognised from its topic names)
// supplies topic names and the extrinsic. Per-point times: point_fields.h (detected from the
// fields, overridable); a cloud without a time field gets azimuth times (logged once). Ground
// truth: nav_msgs/Odometry or geometry_msgs/PoseStamped on `ground_truth_topic`.
//
// Extrinsic T_imu_lidar, in this order (ImuFromLidar, ExtrinsicOrigin):
//   1. (the caller's explicit config value, applied by the odometry runner, not here)
//   2. /tf_static of the bag, when it connects the IMU's and the lidar's header.frame_id;
//   3. the preset's published value;
//   4. identity when the IMU and the lidar messages carry the same frame_id;
// otherwise ImuFromLidar throws, asking for an `extrinsic:` in the config or a preset.
//
// Bad input (std::runtime_error naming the bag and, where it applies, the topic and message
// number): not a bag, a truncated or corrupted bag (the library's error is passed on), a missing
// or ambiguous topic, a topic of the wrong type, a cloud that does not decode (point_fields.h),
// IMU time going backwards, IMU gaps longer than `max_imu_gap_ns` (opt-in; otherwise gaps are
// warnings and the samples are handed on), scans out of order. Duplicate IMU times are dropped
// with a warning.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/driver_conventions.h"
#include "ctlio/io/point_fields.h"

namespace ctlio::io {

struct BagPreset {
  std::string name;         // "newer_college_2020"
  std::string lidar_topic;  // recognised when this topic exists
  std::string imu_topic;
  SE3 imu_from_lidar;
  std::string note;  // one line for --help and the log
};
const std::vector<BagPreset>& BagPresets();

struct BagOptions {
  // "" detects the bag kind from the path; "rosbag" (ROS 1) or "ros2" forces it.
  std::string format;
  std::string lidar_topic, imu_topic;  // empty: the only topic of that type, or the preset's
  std::string preset;                  // empty: recognised from the topics (or none)
  TimeFieldOptions time;
  int64_t max_imu_gap_ns = 0;  // opt-in error for a longer IMU gap; 0 = off (gaps are warned about)
  int64_t imu_gap_warning_ns = 100'000'000;  // a longer gap is logged as a warning
  // Multiplies the accelerometer: 9.80665 for IMUs that report g (Livox), whose mean specific
  // force near 1 is warned about.
  double accel_scale = 1.0;
  // Ground truth T_world_lidar read from this topic (nav_msgs/Odometry or
  // geometry_msgs/PoseStamped) when the bag has it.
  std::string ground_truth_topic = "/ground_truth";
};
using RosbagOptions = BagOptions;

// True if `path` is a regular file starting with the ROS 1 bag magic "#ROSBAG V2.0".
bool IsRosbagFile(const std::string& path);
// True if `path` is a ROS 1 bag or a ROS 2 bag (IsRos2BagPath, bag_stream.h).
bool IsBagPath(const std::string& path);

class BagSource : public DataSource {
 public:
  // A ROS 1 bag file or a ROS 2 bag (folder, .mcap, .db3), as options.format says or detected.
  explicit BagSource(const std::string& path, const BagOptions& options = {});
  // Any message stream (tests: a ROS 2 container in memory); `path` names it in errors.
  BagSource(const std::string& path, std::unique_ptr<BagStream> stream,
            const BagOptions& options = {});
  ~BagSource() override;
  std::string Name() const override;
  size_t NumScans() const override;
  bool Next(ScanFrame* frame) override;
  SE3 ImuFromLidar() const override;
  std::string ExtrinsicOrigin() const override;
  std::optional<std::vector<StampedPose>> GroundTruth() const override;
  std::vector<InputDefect> InputDefects() const override;
  const std::string& lidar_topic() const;
  const std::string& imu_topic() const;
  // Bytes of message data read so far (for throughput reports).
  uint64_t bytes_read() const;
  // Scans read so far that had no usable points or no time spread (empty, all non-finite, all at
  // one instant): each is handed on with its nominal interval, warned about and counted here.
  size_t unusable_scans() const;
  // Scans whose per-point times were not a sweep (point_time_check.h): rescaled by a unit factor
  // or replaced by azimuth times, each with a warning.
  size_t retimed_scans() const;
  // Points dropped for a time more than a scan period (+10 %) from their scan's stamp.
  size_t points_outside_sweep() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};
// The name of the ROS 1 era, for the callers that read ROS 1 bags.
using RosbagSource = BagSource;

struct RosbagWriteOptions {
  std::string lidar_topic = "/os_cloud_node/points";  // ouster_ros names
  std::string imu_topic = "/os_cloud_node/imu";
  std::string lidar_frame = "os_lidar", imu_frame = "os_imu";
  bool write_tf_static = true;       // imu_frame → lidar_frame = source.ImuFromLidar()
  bool write_ground_truth = true;    // topic /ground_truth (nav_msgs/Odometry) if the source has it
  std::string compression = "none";  // chunk compression: none | lz4 | bz2 (read transparently)
  // The lidar driver's cloud (driver_conventions.h): fields and per-point time (Velodyne's cloud
  // is stamped at the scan end, the others at its start) or the Livox CustomMsg.
  PointFormat point_format = PointFormat::kOuster;
  double accel_unit = 1.0;  // the accelerometer is written in units of this many m/s² (g: 9.80665)
  // A driver's format, topics, frames and accelerometer unit; no /tf_static when the lidar and
  // the IMU share a frame (Livox: the extrinsic is the config's).
  void UseDriver(const DriverConvention& d) {
    point_format = d.format;
    lidar_topic = d.lidar_topic;
    imu_topic = d.imu_topic;
    lidar_frame = d.lidar_frame;
    imu_frame = d.imu_frame;
    accel_unit = d.accel_unit;
    write_tf_static = d.lidar_frame != d.imu_frame;
  }
};

// Writes any data source as a bag: each scan as the options' driver writes it (by default an
// Ouster-style PointCloud2: OusterFields, `t` = ns since the stamp = scan start), each IMU sample
// as sensor_msgs/Imu (orientation covariance −1: no orientation), the extrinsic on /tf_static,
// ground truth on /ground_truth. Returns the number of scans. `progress(done, total)` after each
// scan.
size_t WriteRosbag(DataSource& source, const std::string& path,
                   const RosbagWriteOptions& options = {},
                   const std::function<void(size_t, size_t)>& progress = {});

// Writes a trajectory as nav_msgs/Odometry messages on `topic` (frame_id `frame`, child
// `child_frame`), for viewing an estimate in the users' ROS tools.
void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::string& topic = "/ctlio/odometry",
                      const std::string& frame = "map",
                      const std::string& child_frame = "os_lidar");
// The same with each message's pose.covariance (ROS row-major 6×6 over [x y z roll pitch yaw];
// one per pose; lioapp::RosPoseCovariance). Throws std::invalid_argument on a count mismatch.
void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::vector<std::array<double, 36>>& pose_covariances,
                      const std::string& topic = "/ctlio/odometry",
                      const std::string& frame = "map",
                      const std::string& child_frame = "os_lidar");

// ctlio_odometry --write_bag: the estimate in `out_dir` as a bag of the input's kind — a ROS 2 bag
// folder `trajectory_bag/` when `source_name` (DataSource::Name) is a ROS 2 bag's ("ros2bag:..."),
// else the ROS 1 bag `trajectory.bag`; each pose with its covariance (WriteOdometryBag). Returns
// the path and a description for the outputs list.
std::pair<std::string, std::string> WriteEstimateBag(
    const std::string& out_dir, const std::string& source_name,
    const std::vector<StampedPose>& trajectory,
    const std::vector<std::array<double, 36>>& pose_covariances);

}  // namespace ctlio::io
