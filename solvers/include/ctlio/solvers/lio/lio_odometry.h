// Lidar-inertial odometry (SPEC §4–§6): Singer-LIO and its variants, and the IMU-as-input
// baseline, composed of owned parts — the IMU buffer, the lidar front end (voxel map), the
// sliding window, the scan registration, and the estimator of config.method (GP knots or
// navigation states), which only adds states and factors. Per scan (AddScan):
//
//   drop points timed outside the scan's interval → prepare scan → [first scan: initialise
//   gravity and the first state] → marginalise the oldest state → add the new state with its
//   motion/IMU factors → [hold calibration coordinates] → register the keypoints → [release
//   them] → check the estimate → update the map → check the IMU against the lidar's motion →
//   report (with online calibration: observability and σ of the calibration states)
//
// The calibration states' hold, release and report are CalibrationStates' (calibration_states.h).
// One pass over the data: the warm-up replay (calibration.warmup_replay_s) is
// CalibratingOdometry's (calibrating_odometry.h), which runs this pipeline inside; constructed
// here with a replay configured, it throws.
//
// Use: feed the IMU samples in time order with AddImu, and each scan with AddScan once the IMU
// covers its end. Every scan returns a ScanResult whose status says whether the estimate is
// trustworthy (kOk), or why not — the odometry never returns a silent garbage pose: degenerate
// scans, IMU gaps, initialisation failures and implausible input are flagged with a message.
// The input gates (input_checks.h, thresholds in config.input) apply to every caller.
#pragma once

#include <deque>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/calibration_states.h"
#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/final_trajectory.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/imu_buffer.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/pose_covariance_report.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/lio/scan_without_imu.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

class LioOdometry {
 public:
  explicit LioOdometry(const OdometryConfig& config);
  ~LioOdometry();
  LioOdometry(const LioOdometry&) = delete;
  LioOdometry& operator=(const LioOdometry&) = delete;

  // Throws std::invalid_argument if the sample is older than the previous one of its IMU, or of
  // an IMU the config does not declare (OdometryConfig::imus); a duplicate timestamp is dropped
  // and counted in duplicate_imu_samples(). A sample that cannot be physical (not finite, beyond
  // config.input.max_gyro / max_accel) is rejected and counted in the next ScanResult
  // (imu_rejected, message); returns false then.
  bool AddImu(const ImuSample& sample);
  // Processes one scan. Throws std::invalid_argument for a scan out of order or with mismatched
  // point/time arrays; everything else (too few points, IMU gaps, failed initialisation,
  // divergence, points outside the scan's interval, a frozen IMU) is reported in the result.
  ScanResult AddScan(const LidarScan& scan);

  const OdometryConfig& config() const { return config_; }
  // The newest config().kept_results results (all with 0), oldest first: a pipeline that runs
  // for hours keeps a bounded history.
  const std::deque<ScanResult>& results() const { return results_; }
  size_t duplicate_imu_samples() const { return imu_.duplicates(); }
  size_t rejected_imu_samples() const { return imu_.rejected(); }
  bool initialised() const { return initialised_; }
  // Gravity-aligned frame i → map frame m (valid once initialised()).
  const Mat3& C_mi() const { return C_mi_; }
  // The window the pipeline solves (SPEC §5): its states, residual blocks and marginal prior.
  const SlidingWindow& window() const { return window_; }
  SlidingWindow& window() { return window_; }
  // What the most recent Schur-complement marginalisation did (empty before the first one).
  const MarginalizationReport& last_marginalization() const { return last_marginalization_; }
  int num_marginalizations() const { return num_marginalizations_; }
  // The calibration states' part (hold, observability, σ).
  const CalibrationStates& calibration_states() const { return calibration_; }
  // CalibrationStates::HoldUntil: holds the calibration coordinates of `mask` (empty: all) over
  // every scan ending at most t_s seconds after the first scan began.
  void HoldCalibrationUntil(double t_s, std::vector<bool> mask) {
    calibration_.HoldUntil(t_s, std::move(mask));
  }
  // Between scans: the marginal priors forget what they say about the calibration states
  // (SlidingWindow::ForgetInformation; calibration.warmup_forget_s, calibrating_odometry.h).
  // What it replaced; empty without calibration states or a marginal prior on them.
  MarginalizationReport ForgetCalibrationInformation();
  // Between scans: the voxel map is emptied and holds the newest scan's points only (as after the
  // first scan), e.g. when the map was built with a calibration far off.
  void RestartMap();
  // The estimate T_mr sampled every 1/rate_hz s over the newest interval between states: the
  // grid times (multiples of the period in absolute ns) in (previous, newest state) and the newest
  // state's time, whose pose is the scan's T_mr. Empty before the second state.
  std::vector<std::pair<int64_t, SE3>> SampleNewestInterval(double rate_hz) const;
  // What the newest scan inserted into the voxel map: its preprocessed points in the map frame,
  // each moved by the estimated motion at its time (Estimator::MapPoints; the first scan's as
  // prepared, at the origin), the same vector the map was fed, not a copy. nullptr when the
  // newest scan inserted nothing (failed, implausible jump). Valid until the next AddScan.
  const std::vector<Vec3>* newest_map_points() const {
    return map_points_inserted_ ? &map_points_ : nullptr;
  }
  // The dense trajectory from the final estimates (final_trajectory.h): T_mr every 1/rate_hz s
  // (0, the default: none; set before the first scan). TakeFinalTrajectory: the
  // samples of the segments sealed since the previous call, time order; FinalTrajectoryTail: the
  // rest, from the state sealed last to the newest, once no scan follows.
  void SampleFinalTrajectory(double rate_hz) { final_trajectory_.set_rate(rate_hz); }
  FinalTrajectory::Samples TakeFinalTrajectory() { return final_trajectory_.Take(); }
  FinalTrajectory::Samples FinalTrajectoryTail() const;

 private:
  // The extrinsic the next scan is prepared with: its online estimate, or the configured one.
  SE3 CurrentExtrinsic() const;
  // config.overlap_stages: the previous scan's map insertion and, before a registration, the
  // marginalisation, on a second thread; returns their wall ms (map, marginalise), or no future
  // without the overlap.
  std::future<std::pair<double, double>> StartOverlappedStages();
  // config.overlap_stages: inserts map_points_ into the map on a second thread, started
  // as soon as the scan's pose is estimated (map_insertion_ returns its wall ms).
  void StartMapInsertion();
  // First scan: gravity initialisation (with an IMU), the first state, the map.
  void Initialise(const PreparedScan& scan, ScanResult* result);
  // Every later scan.
  void Process(const PreparedScan& scan, ScanResult* result);
  // Schur-complement marginalisation of the oldest states until window_knots − 1 remain, before
  // the new state is added (SPEC §5): their information is kept in one prior, not dropped.
  void Slide(ScanResult* result);
  // The marginalisation of Slide; its wall ms.
  double SlideWindow();
  // A scan is gapped if the IMU(s) the estimator uses all have a hole above init.max_imu_gap
  // in it: for the GP pipelines every IMU (one IMU with data is a measurement of the whole
  // state), for the baseline its input IMU.
  void ReportImuGap(double t_begin, double t_end, ScanResult* result) const;
  // Degenerate directions of the registered lidar term (degeneracy.h): reported in the result;
  // lidar_only and a GP method in an IMU outage keep `predicted` (the newest pose state before
  // registration) along them.
  void AnalyseDegeneracy(const RegistrationSummary& registered, const SE3& predicted,
                         ScanResult* result);
  // Input gate: an IMU whose output stayed bit-identical for config.input.constant_imu_duration
  // while the estimate moved since the previous estimated scan makes the scan kSuspect. Here,
  // not in ImuBuffer: only the odometry knows whether the lidar moved.
  void CheckFrozenImu(ScanResult* result);
  bool uses_imu() const { return config_.method != LioMethod::kLidarOnly; }

  OdometryConfig config_;
  ImuBuffer imu_;
  LidarFrontend frontend_;
  SlidingWindow window_;
  ScanRegistration registration_;
  std::unique_ptr<Estimator> estimator_;
  FinalTrajectory final_trajectory_;  // sealed in SlideWindow, before each marginalisation

  Mat3 C_mi_ = Mat3::Identity();
  int64_t last_scan_end_ns_ = 0;
  SE3 last_pose_;  // T_mr of the newest scan not failed (CheckFrozenImu)
  bool have_last_pose_ = false;
  bool have_origin_ = false;
  bool initialised_ = false;
  std::deque<ScanResult> results_;
  MarginalizationReport last_marginalization_;
  PoseCovarianceModels covariance_models_;  // their state across scans
  CalibrationStates calibration_;
  ScanWithoutImu without_imu_;  // lidar_only, or a scan in an IMU outage
  int num_marginalizations_ = 0;
  PreparedScan prepared_;  // the scan being processed (PrepareScan), its buffers reused
  // Its points in the map frame (MapPoints) and the robot position they are inserted at: on the
  // scan thread, or with config.overlap_stages on the second one (StartMapInsertion).
  std::vector<Vec3> map_points_;
  Vec3 map_position_ = Vec3::Zero();
  bool map_points_inserted_ = false;  // by the newest scan (newest_map_points)
  // The last insertion of a processed scan: points the map kept, and its size after
  // (InsertMapPoints; the map's error as built, window.pose_covariance_map_growth).
  size_t map_points_kept_ = 0;
  size_t map_size_ = 0;
  // config.overlap_stages: whether this scan's marginalisation is done (overlapped with its
  // preprocessing).
  bool slid_ = false;
  // The running map insertion (StartMapInsertion). Last: destroyed first, which waits for it
  // while the map and the points it reads still exist.
  std::future<double> map_insertion_;

  // frontend_.UpdateMap of the newest scan's map points, counting what the map kept.
  void InsertMapPoints();
};

// The pipeline of config.method.
std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config);

}  // namespace ctlio::lio
