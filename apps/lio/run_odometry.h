// Runs a LIO pipeline over a dataset source (a reader or the in-memory simulator): feeds the IMU
// and the scans, collects the per-scan log and the trajectory, times every scan, and evaluates
// against the ground truth when the source has it. Shared by ctlio_odometry and
// ctlio_experiment.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "frame_consistency.h"
#include "trajectory_errors.h"

namespace ctlio::lioapp {

struct RunOptions {
  size_t max_scans = 0;  // 0 = all
  // Extrinsic T_imu_lidar precedence: the config's value when it was given explicitly (true),
  // otherwise the source's (a bag's /tf_static, then a dataset preset or the dataset's files; see
  // DataSource::ExtrinsicOrigin). The choice is logged and kept in RunSummary::extrinsic_origin.
  bool extrinsic_from_config = false;
  // > 0: also sample the estimate at this rate between the scan poses (RunSummary::dense and
  // dense_live).
  double trajectory_rate_hz = 0.0;
  // > 0: each scan is given to the odometry no earlier than its end time after the first scan's,
  // divided by this factor, on the wall clock (1 = the sensor's own pace, as `rosbag play -r`):
  // ScanResult::milliseconds is then the latency from a sweep's arrival to its pose, with the
  // idle time between sweeps what a robot has (window.overlap uses it). 0: back to back.
  double play_rate = 0.0;
  // The calibration warm-up replay (lio::ReplaySchedule, calibrating_odometry.h): on a second
  // thread, adopted with the first scan ending replay_adopt_after_s after the span or at the end
  // of the input, so that the live output does not pause for it; < 0: inside the scan.
  double replay_adopt_after_s = 60.0;
  // Called after every scan with (scans done, scans total or 0, the scan's result).
  std::function<void(size_t, size_t, const lio::ScanResult&)> progress;
  // Called after every scan not failed that inserted points into the odometry's voxel map, with
  // those points (LioOdometry::newest_map_points: map frame, deskewed by the live estimate), for
  // a map output (map_accumulator.h) without a copy. A scan that replayed the calibration
  // warm-up (ScanResult::revised_scans > 0) hands over the replay's points, in the replayed map
  // frame of RunSummary::trajectory: a map starts over there (the warm-up's live points were
  // placed with the calibration the replay revised, a 3° extrinsic error puts them metres off).
  // A replay adopted at the end of the input (replay_adopt_after_s past it) hands over nothing:
  // the map stays the live one.
  std::function<void(const lio::ScanResult&, const std::vector<Vec3>&)> map_points;
  // > 0 (and a method that uses the accelerometer): also run the lidar + gyro reference of
  // accel_reference.h over the first this many scans, with this config (the lidar_gyro one of the
  // run's file; extrinsic, gravity and IMUs are taken from the run's), and judge the accelerometer
  // against it (RunSummary::accel_relabelling). 0: not run (the estimate is the same either way).
  size_t accel_reference_scans = 0;
  std::optional<lio::OdometryConfig> accel_reference_config;
};

struct RunSummary {
  std::string method;
  std::string source;
  std::string extrinsic_origin;  // where T_imu_lidar came from
  // A config extrinsic that differs from the data's (/tf_static, preset, dataset) by more than 1°
  // or 1 cm: "config vs <origin>: 12.3 deg, 4.5 cm (…)", both values (extrinsic_agreement.h).
  std::string extrinsic_disagreement;
  // Estimated T_world_lidar (map frame = IMU frame at the start) at every scan end that was
  // estimated (failed scans are left out, never written as garbage); with the extrinsic
  // estimated online (calibration.estimate_extrinsic), T_mr·T_imu_lidar of that scan's estimate.
  std::vector<io::StampedPose> trajectory;
  // With RunOptions::trajectory_rate_hz: T_world_lidar at that rate from the final estimates
  // (LioOdometry::TakeFinalTrajectory: each segment between two states once both have left the
  // window, the rest at the end; continuous at every state, in pieces around failed scans; with
  // the final extrinsic estimate when it is estimated), and the live,
  // causal one (SampleNewestInterval after every estimated scan, ending at each scan pose as
  // returned; it jumps where the next scan's window revised the previous state).
  std::vector<io::StampedPose> dense;
  std::vector<io::StampedPose> dense_live;
  std::vector<lio::ScanResult> scans;
  // Calibration warm-up replay (calibration.warmup_replay_s): how many earlier scans it revised
  // (0: none), and the trajectory as returned live, scan by scan, before the replay revised its
  // start (the same as `trajectory` without a replay) with its ATE.
  int warmup_replayed_scans = 0;
  // Its cost (CalibratingOdometry::last_replay): CPU on whichever thread ran it, the live
  // thread's wait for it, the scans it processed (passes × span + the catch-up).
  double warmup_replay_cpu_ms = 0.0, warmup_replay_wait_ms = 0.0;
  int warmup_replay_scans = 0;
  std::vector<io::StampedPose> live_trajectory;
  std::vector<lio::ScanResult> warmup_live_scans;  // the replaced results, as returned live
  std::optional<AteResult> live_ate;
  int failed = 0, degenerate = 0, imu_gaps = 0;
  // Scans whose lidar term had at least one degenerate direction (lio/degeneracy.h), whatever
  // their status (with an IMU they stay `ok`: the IMU and the prior carry those directions).
  int degenerate_direction_scans = 0;
  std::string first_failure;  // message of the first failed scan
  // Input gates (lio/input_checks.h, applied by the odometry; totals of the ScanResults):
  // samples rejected, points dropped for their time, scans estimated with a frozen IMU while the
  // lidar moved (status "suspect"; they make the run a failure); and the runner's own recovery:
  // scans skipped because their end is not after the previous one (the odometry would throw).
  int imu_rejected = 0, points_dropped = 0, scans_skipped = 0, constant_imu_scans = 0;
  // Scans whose interval begins before the previous scan's end by more than 10 % of its length
  // (scan times that overlap: a stretched or misplaced interval), counted and warned about by the
  // runner: what follows from them (a failed gravity initialisation, points dropped out of the
  // interval) names its own symptom, not this cause.
  int overlapping_scans = 0;
  std::string first_overlapping_scan;  // the first one's warning
  std::string first_input_warning;     // message of the first of the above
  // The reader's recoveries (DataSource::InputDefects: duplicate IMU times, IMU gaps, points
  // outside their sweep, re-timed sweeps, unusable scans), one entry per kind.
  std::vector<io::InputDefect> input_defects;
  // Settings that are legal but beyond any real sensor (lio/config_plausibility.h).
  std::vector<std::string> config_warnings;
  double median_ms = 0.0, p95_ms = 0.0, max_ms = 0.0;  // wall time per scan (first excluded)
  double median_cpu_ms = 0.0, p95_cpu_ms = 0.0;        // thread CPU time per scan
  // Medians over the scans of the wall-time split (ScanResult::ms_*).
  double median_preprocess_ms = 0.0, median_associate_ms = 0.0, median_solve_ms = 0.0,
         median_map_ms = 0.0, median_marginalize_ms = 0.0;
  long peak_rss_kb = 0;          // process-wide high-water mark (getrusage ru_maxrss) at the end
  std::optional<AteResult> ate;  // when the source has ground truth and ≥ 3 estimates pair with it
  // Drift per 100 m [m]: the mean relative translation error over windows of kDriftWindow m of
  // ground-truth path (half the path when shorter), per 100 m (ctlio::eval RPE over distance,
  // translation_percent); alignment-free. With ground truth and a path of ≥ 1 m.
  std::optional<double> drift_per_100m;
  // Several IMUs: what the method does with them (empty with one IMU), e.g. the baseline's
  // limitation to one IMU. Also logged.
  std::string imu_note;
  // [b_a; b_g] of every IMU at the last estimated scan (Singer-LIO, lidar_gyro), and the true
  // initial biases where the source knows them (simulator).
  std::vector<Vec6> final_biases;
  std::vector<std::optional<Vec6>> true_biases;
  // The true clock offset of every IMU where the source knows it (simulator's stamp_offset), to
  // compare the online calibration's estimate with (ScanResult::calibration).
  std::vector<std::optional<double>> true_time_offsets;
  // The clock offsets the run started from (config.calibration.time_offset_s; empty: 0 for
  // every IMU), the start the online calibration moved from.
  std::vector<double> initial_time_offsets;
  // Consistency (config.pose_covariance and ground truth): per estimated scan after the first,
  // the NEES of the pose, ε = Log(T_mr,true·T_mr⁻¹), εᵀΣ⁻¹ε (6 if consistent), and of its
  // translation and rotation parts alone (3 each), with T_mr,true anchored at the first scan.
  std::vector<double> nees, nees_translation, nees_rotation;
  // Per axis of ε = [ρ; φ]: the scans whose error lies within ±3σ of that axis (of nees.size()).
  std::array<size_t, 6> nees_inside_3sigma{};
  // Extrinsic T_imu_lidar: the one the run started from (config or source), the last estimated
  // one with its marginal σ [ρ; φ] (calibration.estimate_extrinsic; else the starting one, σ 0),
  // and the truth where the source knows it (simulator: DataSource::TrueImuFromLidar).
  SE3 initial_extrinsic, final_extrinsic;
  bool extrinsic_estimated = false;
  Vec6 final_extrinsic_sigma = Vec6::Zero();
  std::optional<SE3> true_extrinsic;
  // Whole-run checks (run_checks.h). A run in which the lidar registered no scan after the first
  // is a failure without an ATE (`ate` and `live_ate` empty): why, here. Lidar gaps (scan ends
  // spaced more than 3× the median) are a warning: their count and the first.
  std::string unregistered_run;
  std::string degenerate_run;  // DegenerateRunWarning (run_checks.h)
  int lidar_gaps = 0;
  std::string first_lidar_gap;
  // IMU–lidar consistency (CheckImuConsistency): the medians over the moving scans, and the
  // warning when they exceed the thresholds (empty otherwise); not a failure.
  int imu_consistency_scans = 0;
  double median_accel_chi2 = 0.0, median_gyro_chi2 = 0.0;
  std::string imu_inconsistency;
  // Lidar–IMU frame consistency (frame_consistency.h): the fits and the warning (empty when
  // consistent or not judged; not run for lidar_only); not a failure.
  FrameConsistency frames;
  // The accelerometer against a lidar + gyro reference (accel_reference.h): its frame fit, the
  // scans it ran over (0: not run) and the warning (empty when nothing stands out).
  FrameConsistency accel_reference;
  int accel_reference_scans = 0;
  std::string accel_relabelling;
  // The method's positions against that reference's (accel_reference.h: RMS, max, path) and the
  // warning when they part by more than the threshold (empty otherwise); not a failure.
  double reference_rms_m = 0.0, reference_max_m = 0.0, reference_path_m = 0.0;
  double reference_estimate_path_m = 0.0, reference_extent_m = 0.0, estimate_extent_m = 0.0;
  std::string reference_ran_off;  // the reference travelled further than the estimate: not judged
  int reference_pairs = 0;
  std::string reference_disagreement;
  // The run is a failure if a scan failed after initialisation, the ATE exceeds `failure_ate`
  // (the estimate left the room of any sensible error), or the lidar registered no scan.
  bool failure = false;
};

RunSummary RunOdometry(io::DataSource& source, lio::OdometryConfig config,
                       const RunOptions& options = {}, double failure_ate = 1.0);

// A dataset frame's sweep as the odometry's input: its points and per-point times are moved out
// of *frame (the rest of the frame stays); a cloud without per-point times gets the scan end for
// every point.
lio::LidarScan TakeLidarScan(io::ScanFrame* frame);

// The config's IMU list from the source's IMUs when the config gives none (`imus:`) and the
// source has more than one IMU or an IMU away from the body frame: each IMU's mounting, and its
// variances scaled from the config's (which describe the first IMU) by the source's stated noise,
// σ_j²/σ_0² (unscaled where the source states none).
void ImusFromSource(const io::DataSource& source, lio::OdometryConfig* config);

// Mean of `v` (NaN if empty).
double Mean(const std::vector<double>& v);

long PeakRssKb();
double Percentile(std::vector<double> v, double p);

}  // namespace ctlio::lioapp
