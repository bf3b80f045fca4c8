// Newer College Dataset 2020 layout (SPEC §6):
//   <seq>/raw_format/ouster_zip_files/ouster_scan/<name>_<sec>_<nsec>.pcd
//       Ouster OS1 fields x y z intensity t reflectivity ring noise range, t = uint32 ns since the
//       stamp in the file name;
//   <seq>/raw_format/ouster_imu/data.csv      header, then counter, sec, nsec, wx wy wz, ax ay az;
//   <seq>/ground_truth/registered_poses.csv   header, then sec, nsec, x y z, qx qy qz qw.
// Ground truth is read as T_world_lidar. Lidar→IMU: the published extrinsic, overridable.
//
// Documented recoveries (logged): duplicate IMU times are dropped; IMU gaps are reported; scans are
// ordered by the stamp in their file names (a directory listing is unordered); points whose time
// is outside [stamp, next stamp] (± 10 % of the scan period) are dropped; a scan without usable
// points (empty, all non-finite, all at one time, no or a wrongly typed time field) is handed on
// empty over its nominal interval. Errors (file and line): missing folders/files, malformed CSV
// lines and PCD files, two scans with one stamp, IMU time going backwards, IMU gaps longer than
// `max_imu_gap_error_ns` when set, ground truth out of order.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/io/dataset.h"

namespace ctlio::io {

// T_imu_lidar of the Newer College 2020 Ouster: rotation diag(−1, −1, 1),
// translation (−0.006253, 0.011775, 0.028535) m (SPEC §6).
SE3 NewerCollegeImuFromLidar();

struct NewerCollegeOptions {
  SE3 imu_from_lidar = NewerCollegeImuFromLidar();
  // A gap in the IMU longer than this is an error (file and line); 0 = off (the default): gaps are
  // logged as warnings and the samples handed on, for the odometry to bridge (it marks the scans
  // concerned by its own per-scan threshold, OdometryConfig::max_imu_gap).
  int64_t max_imu_gap_error_ns = 0;
  bool require_ground_truth = false;  // otherwise a missing registered_poses.csv is logged
};

class NewerCollegeReader : public DataSource {
 public:
  explicit NewerCollegeReader(const std::string& sequence_folder,
                              const NewerCollegeOptions& options = {});
  std::string Name() const override { return "newer_college:" + folder_; }
  size_t NumScans() const override { return scans_.size(); }
  bool Next(ScanFrame* frame) override;
  std::vector<InputDefect> InputDefects() const override;
  SE3 ImuFromLidar() const override { return options_.imu_from_lidar; }
  std::optional<std::vector<StampedPose>> GroundTruth() const override;
  const std::vector<ImuSample>& imu() const { return imu_; }

 private:
  // Repeated per-scan warnings (unusable scans, points outside the interval): the first few in
  // full, then a total at the end of the sequence (warning_limiter.h).
  std::shared_ptr<WarningLimiter> warnings_;
  std::string folder_;
  NewerCollegeOptions options_;
  std::vector<std::pair<int64_t, std::string>> scans_;  // (stamp, path), sorted
  std::vector<ImuSample> imu_;
  std::vector<StampedPose> ground_truth_;
  int64_t nominal_period_ns_ = 100'000'000;  // median stamp spacing (0.1 s with one scan)
  size_t next_ = 0, imu_cursor_ = 0;
};

// Writes any data source in the Newer College layout (scan files named cloud_<sec>_<nsec>.pcd,
// IMU counter from 0, ground truth if the source has it and `write_ground_truth` is set). The
// layout cannot carry an extrinsic: a source whose T_imu_lidar is not the published one is
// refused (the reader would assume the published one).
// `progress(done, total)` is called after each scan. Returns the number of scans written.
size_t WriteNewerCollege(DataSource& source, const std::string& sequence_folder,
                         const std::function<void(size_t, size_t)>& progress = {},
                         bool write_ground_truth = true);

// "<prefix>_<sec>_<nsec>.pcd" → stamp in ns; false if the name does not match.
bool ParseNewerCollegeScanName(const std::string& file_name, int64_t* stamp_ns);

}  // namespace ctlio::io
