// KITTI-style folders:
//   <seq>/velodyne/<index>.bin (float32 x y z reflectance) or <index>_xyz.bin (x y z only),
//   <seq>/times.txt or times_*.txt           scan times [s], one per line (required),
//   <seq>/velodyne_times/<index>.bin         optional per-point times, float32 s since the stamp,
//   <seq>/poses.txt or poses_*.txt           optional ground truth, KITTI cam0 poses,
//   <seq>/calib.txt or calib_*.txt           optional "Tr:" (velodyne→cam0) to turn cam0 poses
//                                            into lidar poses T_w_lidar = Tr⁻¹·P·Tr.
// KITTI odometry has no IMU: scans come with an empty IMU list and identity extrinsic.
//
// Documented recovery when there is no per-point time file (logged once): times are filled from
// each point's azimuth, as the HDL-64E spins clockwise seen from above with the scan stamp at the
// forward (+x) direction: t = stamp − atan2(y, x)/(2π)·period, period 0.1 s.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"

namespace ctlio::io {

class KittiReader : public DataSource {
 public:
  explicit KittiReader(const std::string& folder);
  std::string Name() const override { return "kitti:" + folder_; }
  size_t NumScans() const override { return scans_.size(); }
  bool Next(ScanFrame* frame) override;
  std::vector<InputDefect> InputDefects() const override;
  SE3 ImuFromLidar() const override { return SE3(); }
  std::optional<std::vector<StampedPose>> GroundTruth() const override;

 private:
  // Repeated per-scan warnings (unusable scans, points outside the interval): the first few in
  // full, then a total at the end of the sequence (warning_limiter.h).
  std::shared_ptr<WarningLimiter> warnings_;
  std::string folder_;
  std::vector<std::string> scans_, point_times_;
  std::vector<int64_t> times_;
  std::vector<StampedPose> ground_truth_;
  int floats_per_point_ = 4;
  size_t next_ = 0;
};

}  // namespace ctlio::io
