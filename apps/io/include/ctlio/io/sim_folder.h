// ctlio's own simulator folder layout (docs/user-guide/datasets-and-formats.md):
//   ctlio_sim.yaml        format: ctlio_sim, version: 2, gravity, imu_from_lidar (T_body_lidar),
//                         optional true_imu_from_lidar (the truth when imu_from_lidar is a
//                         perturbed nominal one, sim/extrinsic_error.h),
//                         imus (per IMU: name, file, body_from_imu, rate_hz, accel_noise,
//                         gyro_noise, optional true accel_bias/gyro_bias), free `config`
//   imu.csv               header "t_ns,wx,wy,wz,ax,ay,az": the first IMU (imu1.csv, imu2.csv, ...
//                         the others, same header)
// Version 1 (no `imus`: one IMU in imu.csv, in the body frame) is still read.
//   scans.csv             header "index,start_ns,end_ns,points,file"
//   scans/<index>.bin     per point: float32 x y z (lidar frame), uint32 ns since start_ns
//   ground_truth.csv      header "t_ns,x,y,z,qx,qy,qz,qw" (T_world_lidar), optional
//   ground_truth_tum.txt  the same poses in TUM format, for ctlio_evaluate
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"

namespace ctlio::io {

class SimFolderReader : public DataSource {
 public:
  // `max_imu_gap_error_ns`: IMU gaps longer than this are errors; 0 (default) = gaps are logged
  // as warnings and the samples handed on (CheckImuStream).
  explicit SimFolderReader(const std::string& folder, int64_t max_imu_gap_error_ns = 0);
  std::string Name() const override { return "ctlio_sim:" + folder_; }
  size_t NumScans() const override { return scans_.size(); }
  bool Next(ScanFrame* frame) override;
  std::vector<InputDefect> InputDefects() const override;
  SE3 ImuFromLidar() const override { return imu_from_lidar_; }
  std::optional<SE3> TrueImuFromLidar() const override { return true_imu_from_lidar_; }
  std::optional<std::vector<StampedPose>> GroundTruth() const override;
  std::optional<double> Gravity() const override { return gravity_; }
  std::vector<ImuInfo> Imus() const override { return imus_; }
  int version() const { return version_; }
  // Every IMU sample of the folder, time-sorted, tagged with its IMU.
  const std::vector<ImuSample>& imu() const { return imu_; }

 private:
  struct ScanEntry {
    int line;
    int64_t start_ns, end_ns;
    size_t points;
    std::string file;
  };
  // Repeated per-scan warnings (unusable scans, points outside the interval): the first few in
  // full, then a total at the end of the sequence (warning_limiter.h).
  std::shared_ptr<WarningLimiter> warnings_;
  std::string folder_;
  SE3 imu_from_lidar_;
  std::optional<SE3> true_imu_from_lidar_;
  double gravity_ = 9.81;
  int version_ = 1;
  std::vector<ImuInfo> imus_;
  std::vector<ScanEntry> scans_;
  std::vector<ImuSample> imu_;
  std::vector<StampedPose> ground_truth_;
  size_t next_ = 0, imu_cursor_ = 0;
};

// Writes any data source in the layout above (version 2, one CSV per IMU of source.Imus()).
// `config_yaml` (a YAML mapping, may be empty) is stored under the key `config` of ctlio_sim.yaml
// to record how the data were made. Ground truth is written if the source has it and
// `write_ground_truth` is set.
size_t WriteSimFolder(DataSource& source, const std::string& folder,
                      const std::string& config_yaml = "",
                      const std::function<void(size_t, size_t)>& progress = {},
                      bool write_ground_truth = true);

// Reads/writes one scan file of the layout (stamp = start_ns).
PointCloud ReadSimScan(const std::string& path, int64_t start_ns);
void WriteSimScan(const std::string& path, const PointCloud& cloud);

}  // namespace ctlio::io
