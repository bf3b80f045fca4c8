// The one interface the odometry consumes (SPEC §6–7 datasets): a sequence of lidar scans with
// ABSOLUTE int64-ns per-point times (SPEC §1), the IMU samples between consecutive scans, the
// lidar→IMU extrinsic and optional ground truth. Implemented by every dataset reader (Newer College
// 2020, ctlio's simulator folder, KITTI) and by the in-memory simulator source (apps/sim).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/factors/imu/imu_data.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::io {

// One IMU sample in the IMU frame: angular rate [rad/s] and specific force [m/s²]. The same type
// as the factors' and the odometry's (no conversion anywhere).
using ImuSample = imu::ImuSample;

// One IMU of a dataset. The robot (body) frame of the odometry is the frame ImuFromLidar()
// maps lidar points into; with one IMU it is that IMU's frame (T_body_imu = identity), with
// several each IMU sits at its own T_body_imu (rotation and lever arm).
struct ImuInfo {
  std::string name = "imu0";
  SE3 T_body_imu;        // maps IMU coordinates into the body frame
  double rate_hz = 0.0;  // nominal rate (0 = unknown)
  // Per-sample standard deviations when the dataset states them (0 = unknown).
  double accel_sigma = 0.0;  // m/s²
  double gyro_sigma = 0.0;   // rad/s
  // The true initial biases [b_a; b_g] when known (simulated data), for evaluation only.
  std::optional<Vec6> true_bias;
  // The true clock offset δ when known (simulated data, for evaluation only): a sample stamped t
  // measures the motion at t + δ (what the odometry's calibration.time_offset_s should find).
  std::optional<double> true_time_offset_s;
};

// A timestamped pose. In ground truth it is T_world_lidar: the lidar frame's pose in a fixed world
// frame (maps lidar coordinates into world coordinates, SPEC §1).
struct StampedPose {
  int64_t t_ns = 0;
  SE3 pose;
};

// One lidar scan plus the IMU samples with times in (end of the previous scan, end of this scan];
// the first scan also gets every earlier sample. With several IMUs the samples of all of them
// are in one time-sorted list, each tagged with ImuSample::imu. `cloud.times_ns` are absolute and
// always present (sources without per-point times are rejected or documented to fill them).
struct ScanFrame {
  size_t index = 0;
  int64_t start_ns = 0;  // scan stamp (= cloud.stamp_ns)
  int64_t end_ns = 0;    // the latest per-point time
  PointCloud cloud;      // lidar frame
  std::vector<ImuSample> imu;
};

struct InputDefect;  // warning_limiter.h

class DataSource {
 public:
  virtual ~DataSource() = default;
  // Short human-readable description ("newer_college:/path", "sim:fast/03", ...).
  virtual std::string Name() const = 0;
  // Number of scans, if known in advance (0 = unknown).
  virtual size_t NumScans() const = 0;
  // Fills the next scan; false when the sequence is exhausted. Throws std::runtime_error (naming
  // file and line) on bad input.
  virtual bool Next(ScanFrame* frame) = 0;
  // T_imu_lidar: maps lidar coordinates into the IMU frame.
  virtual SE3 ImuFromLidar() const = 0;
  // Where ImuFromLidar comes from, for the log ("dataset files", "bag /tf_static", "preset ...").
  virtual std::string ExtrinsicOrigin() const { return "the dataset (" + Name() + ")"; }
  // The true T_imu_lidar where the source knows it (simulator), which may differ from the
  // nominal ImuFromLidar (calibration experiments).
  virtual std::optional<SE3> TrueImuFromLidar() const { return std::nullopt; }
  // Ground truth T_world_lidar, time-sorted, if the source has it.
  virtual std::optional<std::vector<StampedPose>> GroundTruth() const { return std::nullopt; }
  // Gravity magnitude the IMU data assume, if the source knows it (simulator: exact value).
  virtual std::optional<double> Gravity() const { return std::nullopt; }
  // The IMUs whose samples the scans carry (ImuSample::imu indexes this list); one IMU in the
  // body frame unless the source says otherwise.
  virtual std::vector<ImuInfo> Imus() const { return {ImuInfo{}}; }
  // The input defects the reader recovered from so far (warning_limiter.h: duplicate IMU times,
  // IMU gaps, points outside their sweep, re-timed sweeps, unusable scans, ...), one entry per
  // kind; the runner writes them into evaluation.txt. Sources without recoveries: none.
  virtual std::vector<InputDefect> InputDefects() const;
};

// The samples of several time-sorted IMU streams in one time-sorted list, each sample tagged
// with its stream's index (at equal times the lower index first).
std::vector<ImuSample> MergeImuStreams(const std::vector<std::vector<ImuSample>>& streams);

// Groups a time-sorted IMU stream and scans: appends the samples with start < t ≤ end to *out,
// advancing *cursor. Used by every reader so that "IMU between scans" means the same everywhere.
void TakeImuUntil(const std::vector<ImuSample>& imu, int64_t end_ns, size_t* cursor,
                  std::vector<ImuSample>* out);

// For the single-IMU layouts (Newer College, ROS bag): they hold the first IMU only, whose frame
// must be the body frame; throws naming `target` otherwise and warns that further IMUs are left
// out.
void RequireFirstImuInBodyFrame(const DataSource& source, const std::string& target);

class WarningLimiter;  // warning_limiter.h

// Recovery shared by the readers: drops the points of `cloud` timed outside [lo_ns, hi_ns] (the
// scan's interval with a tolerance), with a warning naming `path` (the first few of the sequence
// only when `warnings` is given: the reader's limiter). Returns how many.
size_t DropPointsOutside(const std::string& path, int64_t lo_ns, int64_t hi_ns, PointCloud* cloud,
                         WarningLimiter* warnings = nullptr);

// Checks an IMU stream read from `path` (lines[i] = line number of imu[i]) and applies the
// documented recoveries, logged with glog and counted in `warnings` (the reader's limiter, whose
// InputDefects the run reports; null: a limiter of its own):
//   * a sample with the same time as the previous one (duplicate) is dropped, with a warning;
//   * a time going backwards is an error "<path>:<line>: IMU time goes backwards ...";
//   * a gap (spacing above 3× the median) is a warning "<path>:<line>: gap of ... s in the IMU"
//     and the samples are handed on; with `max_gap_error_ns` > 0 a gap longer than that is an
//     error "<path>:<line>: gap of ... in the IMU" (opt-in: --max_imu_gap_error).
void CheckImuStream(const std::string& path, const std::vector<int>& lines,
                    int64_t max_gap_error_ns, std::vector<ImuSample>* imu,
                    WarningLimiter* warnings = nullptr);

// Decimal seconds (as in TUM files) to int64 ns without going through double, so that
// 1583836591.182590000 stays exact. Returns false if `s` is not a decimal number.
bool ParseSecondsNs(const std::string& s, int64_t* ns);
std::string FormatSecondsNs(int64_t ns);  // "<sec>.<9 digits>"
// Seconds (double) to int64 ns, rounded; false if `s` is not finite or |s| ≥ 9.2e9 s (the int64
// nanosecond range), where the conversion would overflow.
bool SecondsToNs(double s, int64_t* ns);
// sec·10⁹ + nsec with 0 ≤ nsec < 10⁹ and no overflow; false otherwise.
bool SecNsecToNs(int64_t sec, int64_t nsec, int64_t* ns);

// Opens any supported dataset by looking at it: a folder of Newer College 2020 (raw_format/),
// ctlio's simulator (ctlio_sim.yaml) or KITTI (velodyne/), or a file or ROS 2 bag folder handed
// to the registered file opener (ROS 1/2 bags with ctlio::io_rosbag linked: rosbag_source.h, as
// ctlio_odometry finds them without flags). Throws naming `path` if none matches.
// `max_imu_gap_error_ns`: the readers' opt-in IMU gap error (0 = gaps are warnings).
std::unique_ptr<DataSource> OpenDataset(const std::string& path, int64_t max_imu_gap_error_ns = 0);

// The reader OpenDataset hands a regular file to. ctlio::io keeps no ROS dependency, so the bag
// reader lives in ctlio::io_rosbag, which registers itself here when it is linked (its link
// interface forces the registering object in); programs never call this themselves.
using DatasetFileOpener = std::unique_ptr<DataSource> (*)(const std::string& path,
                                                          int64_t max_imu_gap_error_ns);
void RegisterDatasetFileOpener(DatasetFileOpener opener);

}  // namespace ctlio::io
