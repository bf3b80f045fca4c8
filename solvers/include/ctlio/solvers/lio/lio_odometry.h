// Lidar-inertial odometry (SPEC §4–§6): Singer-LIO and its variants, and the IMU-as-input
// baseline, composed of owned parts — the IMU buffer, the lidar front end (voxel map), the
// sliding window, the scan registration, and the estimator of config.method (GP knots or
// navigation states), which only adds states and factors. Per scan (AddScan):
//
//   drop points timed outside the scan's interval → prepare scan → [first scan: initialise
//   gravity and the first state] → marginalise the oldest state → add the new state with its
//   motion/IMU factors → register the keypoints → check the estimate → update the map → check
//   the IMU against the lidar's motion → report
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
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/calibration_observability.h"
#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/final_trajectory.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/imu_buffer.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"
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

  // After a warm-up replay (calibration.warmup_replay_s) everything below is the replayed
  // pipeline's, which carries on: its config starts the calibration from the warm-up's estimates.
  const OdometryConfig& config() const { return active().config_; }
  // The newest config().kept_results results (all with 0), oldest first: a pipeline that runs
  // for hours keeps a bounded history. While a warm-up replay is pending, every result of its
  // span stays, and after it the replayed span's results are all here (the replay revised them).
  const std::deque<ScanResult>& results() const { return active().results_; }
  // The results returned live for the scans of the warm-up span, before the replay replaced
  // them in results() (empty until a replay).
  const std::deque<ScanResult>& warmup_results() const { return warmup_results_; }
  size_t duplicate_imu_samples() const { return active().imu_.duplicates(); }
  size_t rejected_imu_samples() const { return active().imu_.rejected(); }
  bool initialised() const { return active().initialised_; }
  // Gravity-aligned frame i → map frame m (valid once initialised()).
  const Mat3& C_mi() const { return active().C_mi_; }
  // The window the pipeline solves (SPEC §5): its states, residual blocks and marginal prior.
  const SlidingWindow& window() const { return active().window_; }
  SlidingWindow& window() { return replay_ != nullptr ? replay_->window_ : window_; }
  // What the most recent Schur-complement marginalisation did (empty before the first one).
  const MarginalizationReport& last_marginalization() const {
    return active().last_marginalization_;
  }
  int num_marginalizations() const { return active().num_marginalizations_; }
  // The estimate T_mr sampled every 1/rate_hz s over the newest interval between states: the
  // grid times (multiples of the period in absolute ns) in (previous, newest state) and the newest
  // state's time, whose pose is the scan's T_mr. Empty before the second state.
  std::vector<std::pair<int64_t, SE3>> SampleNewestInterval(double rate_hz) const;
  // What the newest scan inserted into the voxel map: its preprocessed points in the map frame,
  // each moved by the estimated motion at its time (Estimator::MapPoints; the first scan's as
  // prepared, at the origin), the same vector the map was fed, not a copy. nullptr when the
  // newest scan inserted nothing (failed, implausible jump). Valid until the next AddScan.
  const std::vector<Vec3>* newest_map_points() const {
    return active().map_points_inserted_ ? &active().map_points_ : nullptr;
  }
  // The dense trajectory from the final estimates (final_trajectory.h): T_mr every 1/rate_hz s
  // (0, the default: none; set before the first scan). A warm-up replay's pipeline carries it on
  // from its own first scan (the replay revised the span's estimates). TakeFinalTrajectory: the
  // samples of the segments sealed since the previous call, time order; FinalTrajectoryTail: the
  // rest, from the state sealed last to the newest, once no scan follows.
  void SampleFinalTrajectory(double rate_hz) { final_trajectory_.set_rate(rate_hz); }
  FinalTrajectory::Samples TakeFinalTrajectory();
  FinalTrajectory::Samples FinalTrajectoryTail() const;

 private:
  const LioOdometry& active() const { return replay_ != nullptr ? *replay_ : *this; }
  // AddScan's work on a checked scan.
  ScanResult RunScan(const LidarScan& input);
  // Warm-up replay: true while the data is kept for it.
  bool KeepsWarmup() const { return config_.calibration.replays_warmup() && !warmup_done_; }
  // After `result`'s scan: once the kept data spans warmup_replay_s and the scan was estimated,
  // processes it again in replay_ from the estimates in `result` and replaces `result` with the
  // replay's; gives up (note, data dropped) if twice the span passes without an estimate.
  void MaybeReplayWarmup(ScanResult* result);
  // The config of a replay pass started from `estimate` (calibration.warmup_replay_s).
  OdometryConfig ReplayConfig(const ScanResult::CalibrationEstimate& estimate) const;
  // What a frozen pass with `config` (ReplayConfig(estimate)) reports: its values, the
  // estimate's σ, every coordinate marked held.
  static ScanResult::CalibrationEstimate Frozen(const ScanResult::CalibrationEstimate& estimate,
                                                const OdometryConfig& config);
  void CheckScan(const LidarScan& scan) const;
  // Input gate: the points timed outside [interval start − tolerance, end + tolerance]
  // (config.input.scan_time_tolerance; the interval starts at the previous scan's end once
  // initialised) are dropped into *trimmed, which is returned with *note saying so; `scan` itself
  // when none is.
  const LidarScan& DropPointsOutsideInterval(const LidarScan& scan, LidarScan* trimmed,
                                             std::string* note) const;
  // Robot-frame points (T_robot_lidar: the extrinsic or its estimate), range gate, voxel
  // subsampling, keypoints, time order. Times within the tolerance outside the interval (driver
  // clock jitter) are clamped onto it. Into prepared_ (its buffers' capacity is reused: fresh
  // megabyte vectors per scan were page faults in every scan), which the reference returned is.
  const PreparedScan& PrepareScan(const LidarScan& scan, const SE3& T_robot_lidar);
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
  // With config.pose_covariance: Σ of the newest pose into the result (left perturbation of T_mr).
  void ReportPoseCovariance(ScanResult* result);
  // With online calibration: the marginal σ of the calibration states (clock offsets, extrinsic)
  // into result->calibration: the inverse of their marginal information in the whole window
  // (MarginalInformation), the window's pseudo-inverse; NaN when that is not positive definite.
  void ReportCalibrationCovariance(ScanResult* result);
  // With online calibration and calibration.observability_horizon_scans > 0: the newest
  // interval's information on the calibration coordinates into the horizon
  // (calibration_observability.h), ν and the unobservable ones into result->calibration.
  void AssessCalibrationObservability(ScanResult* result);
  // Before the registration: a strong prior at the current value along every coordinate the
  // previous scan left unobservable (calibration.hold_unobservable), or along those of
  // hold_mask_ when the scan ends (t_end: seconds since the first scan began) within
  // hold_calibration_until_s_, so that the solve does not move it; ReleaseCalibration removes
  // them after the solve.
  void HoldCalibration(double t_end, ScanResult* result);
  void ReleaseCalibration();
  // The calibration states the estimator keeps in the window (the baseline has none), in the
  // order of the coordinates: the clock offsets (1-D each), then the extrinsic T_imu_lidar.
  std::vector<StateId> CalibrationStates() const;
  // Creates observability_ over the calibration states in the window; false when there are none
  // or the check is off.
  bool StartObservability();
  // False (and the scan failed) if the newest pose jumped implausibly far.
  bool EstimatePlausible(ScanResult* result) const;
  void ReportDegenerate(ScanResult* result) const;
  // Degenerate directions of the registered lidar term (degeneracy.h): reported in the result;
  // lidar_only keeps `predicted` (the newest pose state before registration) along them.
  void AnalyseDegeneracy(const RegistrationSummary& registered, const SE3& predicted,
                         ScanResult* result);
  // lidar_only with a degenerate direction: the scan is `degenerate` (remapped or not).
  void ReportDegenerateDirections(ScanResult* result) const;
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
  // Online calibration's observability (created at the first assessment) over the states of
  // CalibrationStates(), and the hold priors of this scan.
  std::unique_ptr<CalibrationObservability> observability_;
  std::vector<ceres::ResidualBlockId> holds_;
  int num_marginalizations_ = 0;
  PreparedScan prepared_;  // the scan being processed (PrepareScan), its buffers reused
  // Its points in the map frame (MapPoints) and the robot position they are inserted at: on the
  // scan thread, or with config.overlap_stages on the second one (StartMapInsertion).
  std::vector<Vec3> map_points_;
  Vec3 map_position_ = Vec3::Zero();
  bool map_points_inserted_ = false;  // by the newest scan (newest_map_points)
  // config.overlap_stages: whether this scan's marginalisation is done (overlapped with its
  // preprocessing).
  bool slid_ = false;
  // Warm-up replay (calibration.warmup_replay_s): every IMU sample and scan of the span as given
  // (each scan with the number of samples added before it), the pipeline that replayed them
  // (every call is forwarded to it from then on), and the live results it replaced.
  std::vector<ImuSample> warmup_imu_;
  std::vector<std::pair<LidarScan, size_t>> warmup_scans_;
  std::unique_ptr<LioOdometry> replay_;
  std::deque<ScanResult> warmup_results_;
  bool warmup_done_ = false;
  // Set on the last pass of a held warm-up replay (calibration.warmup_replay_hold): the span,
  // and which coordinates to hold (those observable when the pass started; empty: all).
  double hold_calibration_until_s_ = -1.0;
  std::vector<bool> hold_mask_;
  // Set on the last pass of a frozen warm-up replay (calibration.warmup_replay_freeze): the
  // values it runs with and their σ, reported with every result as held.
  std::optional<ScanResult::CalibrationEstimate> frozen_calibration_;
  // The running map insertion (StartMapInsertion). Last: destroyed first, which waits for it
  // while the map and the points it reads still exist.
  std::future<double> map_insertion_;
};

// The pipeline of config.method.
std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config);

}  // namespace ctlio::lio
