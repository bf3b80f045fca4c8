#include "ctlio/solvers/lio/lio_odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/degeneracy.h"
#include "ctlio/solvers/lio/gravity_alignment.h"
#include "ctlio/solvers/lio/imu_consistency.h"
#include "ctlio/solvers/lio/input_checks.h"
#include "ctlio/solvers/lio/pose_covariance_report.h"
#include "ctlio/solvers/lio/registration_budget.h"
#include "ctlio/solvers/lio/scan_preparation.h"
#include "ctlio/solvers/lio/scan_status.h"
#include "ctlio/solvers/lio/state_keys.h"
#include "scan_clock.h"

namespace ctlio::lio {

using internal::AddNote;
using internal::MsSince;
using internal::ThreadCpuMs;

namespace {

const OdometryConfig& Validated(const OdometryConfig& config) {
  config.Validate();
  if (config.calibration.replays_warmup() || config.calibration.forgets_warmup()) {
    throw std::invalid_argument(
        "LioOdometry: calibration.warmup_replay_s / warmup_forget_s > 0 need CalibratingOdometry "
        "(calibrating_odometry.h), which runs the warm-up's replay or forgetting around this pass");
  }
  return config;
}

// Dense normal Cholesky: a window of two or three knots has < 60 tangent parameters, where the
// dense factorisation beats SuiteSparse's symbolic overhead.
SlidingWindowOptions WindowOptions(const OdometryConfig& config) {
  SlidingWindowOptions o;
  o.solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  o.solver.max_num_iterations = config.frontend.solver_iterations;
  // window.threads go to the window's own work (interpolations, lidar rows) on ParallelFor's
  // persistent helpers; Ceres' evaluation stays on one thread: its thread pool wakes its workers
  // per loop, which cost more than they saved here (docs/experiments/latency.md).
  o.threads = config.solver_threads;
  o.solver.minimizer_progress_to_stdout = false;
  o.solver.logging_type = ceres::SILENT;
  return o;
}

std::vector<Vec3> Positions(const std::vector<TimedPoint>& points) {
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const TimedPoint& p : points) out.push_back(p.point);
  return out;
}

}  // namespace

LioOdometry::LioOdometry(const OdometryConfig& config)
    : config_(Validated(config)),
      imu_(config_.input),
      frontend_(config.frontend),
      window_(WindowOptions(config)),
      registration_(config.frontend, config.min_associations),
      estimator_(MakeEstimator(config_, imu_)),
      calibration_(config_.calibration, config_.num_imus()) {}

LioOdometry::~LioOdometry() = default;

std::vector<std::pair<int64_t, SE3>> LioOdometry::SampleNewestInterval(double rate_hz) const {
  std::vector<std::pair<int64_t, SE3>> out;
  if (!initialised_ || rate_hz <= 0.0 || estimator_->num_states() < 2) return out;
  const int64_t origin = imu_.origin_ns();
  const int64_t begin = origin + std::llround(estimator_->previous_time() * 1e9);
  const int64_t end = origin + std::llround(estimator_->newest_time() * 1e9);
  const int64_t period = std::max<int64_t>(1, std::llround(1e9 / rate_hz));
  std::vector<int64_t> ns;
  for (int64_t t = (begin / period + 1) * period; t < end; t += period) ns.push_back(t);
  ns.push_back(end);
  std::vector<double> t;
  t.reserve(ns.size());
  for (const int64_t x : ns) t.push_back(imu_.Seconds(x));
  const std::vector<SE3> poses = estimator_->PosesSincePrevious(t);
  for (size_t i = 0; i < ns.size(); ++i) out.emplace_back(ns[i], poses[i]);
  return out;
}

FinalTrajectory::Samples LioOdometry::FinalTrajectoryTail() const {
  if (!initialised_) return {};
  return final_trajectory_.Tail(*estimator_, imu_.origin_ns());
}

bool LioOdometry::AddImu(const ImuSample& sample) {
  if (sample.imu >= config_.num_imus()) {
    throw std::invalid_argument("LioOdometry::AddImu: sample of IMU " + std::to_string(sample.imu) +
                                ", the config declares " + std::to_string(config_.num_imus()) +
                                " (imus:)");
  }
  return imu_.AddImu(sample);
}

ScanResult LioOdometry::AddScan(const LidarScan& input) {
  CheckScan(input, have_origin_ ? &last_scan_end_ns_ : nullptr);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMs();
  if (!have_origin_) {
    imu_.SetOrigin(input.begin_ns);
    have_origin_ = true;
  }
  ScanResult result;
  map_points_inserted_ = false;
  LidarScan trimmed;
  std::string dropped_note;  // added to the message once the scan is processed
  // The interval the scan's points must lie in starts at the previous scan's end once initialised.
  const int64_t interval_begin = initialised_ ? last_scan_end_ns_ : input.begin_ns;
  const LidarScan& scan = DropPointsOutsideInterval(
      input, interval_begin, config_.input.scan_time_tolerance, &trimmed, &dropped_note);
  result.points_dropped = static_cast<int>(input.points.size() - scan.points.size());
  const SE3 T_robot_lidar = CurrentExtrinsic();
  std::future<std::pair<double, double>> overlapped = StartOverlappedStages();
  // With the overlap the second core runs the previous scan's map insertion and the
  // marginalisation meanwhile (StartOverlappedStages): a second range-gate thread would only
  // contend with them for the two cores (docs/experiments/latency.md: preprocessing 6.4 against
  // 4.7 ms).
  PrepareScan(scan, T_robot_lidar, interval_begin, imu_,
              config_.overlap_stages ? 1 : config_.frontend.threads, &frontend_, &prepared_);
  const PreparedScan& prepared = prepared_;
  result.ms_preprocess = MsSince(start);
  result.t_ns = scan.end_ns;
  result.keypoints = static_cast<int>(prepared.keypoints.size());
  // The states this scan adds have times in (previous scan end, scan end].
  const bool had_state = initialised_;
  const double t_previous = imu_.Seconds(last_scan_end_ns_);
  try {
    // Joined before anything reads the map or the window; rethrows what the thread threw. The
    // second thread's times go into this scan's map and marginalise columns.
    if (overlapped.valid()) {
      const auto [ms_map, ms_marginalize] = overlapped.get();
      result.ms_map += ms_map;
      result.ms_marginalize += ms_marginalize;
    }
    if (!initialised_) {
      Initialise(prepared, &result);
    } else {
      Process(prepared, &result);
    }
    last_scan_end_ns_ = scan.end_ns;
  } catch (const std::exception& e) {
    result.status = ScanStatus::kFailed;
    result.message = e.what();
    if (!initialised_) last_scan_end_ns_ = scan.end_ns;
  }
  if (!dropped_note.empty()) AddNote(&result, dropped_note);
  if (had_state && result.status == ScanStatus::kFailed) {
    final_trajectory_.MarkFailed(t_previous, prepared.t_end);
  }
  const ImuBuffer::Rejections rejected = imu_.TakeRejections();
  if (rejected.count > 0) {
    result.imu_rejected = static_cast<int>(rejected.count);
    AddNote(&result,
            std::to_string(rejected.count) +
                " IMU sample(s) rejected since the previous scan (first: " + rejected.first + ")");
  }
  CheckFrozenImu(&result);
  imu_.Trim(imu_.Seconds(last_scan_end_ns_) - 0.5);
  result.milliseconds = MsSince(start);
  result.cpu_ms = ThreadCpuMs() - cpu_start;
  results_.push_back(result);
  if (config_.kept_results > 0) {
    while (results_.size() > config_.kept_results) results_.pop_front();
  }
  return result;
}

void LioOdometry::CheckFrozenImu(ScanResult* result) {
  if (result->status == ScanStatus::kFailed) return;
  const double constant = imu_.ConstantSeconds();
  if (uses_imu() && have_last_pose_ && constant >= config_.input.constant_imu_duration &&
      PoseMoved(last_pose_, result->T_mr, config_.input)) {
    std::ostringstream m;
    m << "IMU output constant for " << constant
      << " s while the lidar moves (frozen or dead IMU; input.constant_imu_duration)";
    result->status = ScanStatus::kSuspect;
    AddNote(result, m.str());
  }
  last_pose_ = result->T_mr;
  have_last_pose_ = true;
}

void LioOdometry::Initialise(const PreparedScan& scan, ScanResult* result) {
  std::string message;
  if (uses_imu() && !InitialiseGravity(imu_, scan.t_end, config_, &C_mi_, &message)) {
    result->status = ScanStatus::kFailed;
    result->message = message;
    return;
  }
  estimator_->Initialise(scan, C_mi_, &window_);
  map_points_ = Positions(scan.points);
  frontend_.UpdateMap(map_points_, Vec3::Zero());
  map_points_inserted_ = true;
  initialised_ = true;
  estimator_->Report(result);
  if (result->status == ScanStatus::kOk) result->status = ScanStatus::kInitialising;
}

void LioOdometry::Process(const PreparedScan& scan, ScanResult* result) {
  Slide(result);
  ReportImuGap(estimator_->newest_time(), scan.t_end, result);
  estimator_->AddState(scan, &window_, result);

  // The prediction in the window's parametrisation (T_rm for the GP methods), which the
  // degeneracy remapping's prior is on, and as the robot's pose in the map (T_mr).
  const SE3 predicted = window_.Pose(estimator_->NewestPoseKey());
  const SE3 predicted_mr = estimator_->NewestPose();
  without_imu_.Begin(ScanWithoutImu::Applies(config_.method, *result), estimator_->NewestKeys(),
                     window_);
  const std::unique_ptr<LidarTerm> lidar = estimator_->MakeLidarTerm(scan, &window_);
  result->keypoints = static_cast<int>(lidar->num_keypoints());  // a sweep's own budget
  calibration_.Hold(scan.t_end, &window_, result);
  const double speed = PredictedSpeed(estimator_->PreviousPose(), predicted_mr,
                                      estimator_->newest_time() - estimator_->previous_time());
  const RegistrationSummary registered =
      RegisterWithin(ScanBudget(config_.frontend, without_imu_.active(), speed), registration_,
                     frontend_.map(), lidar.get(), &window_);
  calibration_.Release(&window_);
  if (!registered.degenerate) AnalyseDegeneracy(registered, predicted, result);
  result->rounds = registered.rounds;
  result->solver_iterations = registered.solver_iterations;
  result->associations = registered.associations;
  result->final_cost = registered.final_cost;
  result->ms_associate = registered.ms_associate;
  result->ms_solve = registered.ms_solve;
  // The IMU terms' own χ² at the final estimate, for the run's consistency check (run_checks.h).
  ChiSquare accel, gyro;
  EvaluateImuChiSquare(&window_.problem(), estimator_->NewestImuBlocks(), &accel, &gyro);
  result->accel_chi2 = accel.chi2;
  result->accel_dof = accel.dof;
  result->gyro_chi2 = gyro.chi2;
  result->gyro_dof = gyro.dof;

  const auto t_map = std::chrono::steady_clock::now();
  const size_t kept = std::exchange(map_points_kept_, 0), map_size = map_size_;
  const SE3 T_mr = estimator_->NewestPose();
  result->correction_m = (T_mr.translation() - predicted_mr.translation()).norm();
  result->correction_rad = so3::Log(predicted_mr.rotation().transpose() * T_mr.rotation()).norm();
  const bool plausible =
      CheckPlausibleJump((T_mr.translation() - estimator_->PreviousPose().translation()).norm(),
                         T_mr.translation().allFinite(), config_.max_scan_translation, result);
  const bool rejected =
      plausible && without_imu_.RejectsCorrection(uses_imu(), config_.frontend, result);
  const bool restored = (!plausible || rejected) && without_imu_.Restore(registered, &window_);
  if (plausible && !rejected) {
    estimator_->MapPoints(scan, &map_points_);
    map_position_ = T_mr.translation();
    map_points_inserted_ = true;
    if (config_.overlap_stages) {
      // Inserted on a second thread from now on: in real time, while the robot waits for the
      // next sweep; back to back, beside the rest of this scan and the next one's preprocessing.
      // Joined before anything reads the map (StartOverlappedStages' task, or RunScan).
      StartMapInsertion();
    } else {
      InsertMapPoints();
    }
  }
  if (registered.degenerate) MarkTooFewAssociations(config_.min_associations, uses_imu(), result);
  if (!uses_imu() && result->degeneracy.num_degenerate() > 0) MarkDegenerateDirections(result);
  result->ms_map += MsSince(t_map);
  estimator_->Report(result);
  // The previous scan's insertion, joined by now in either mode (map_growth_covariance.h).
  if (config_.pose_covariance) {
    covariance_models_.growth.Inserted(kept, map_size, config_.pose_covariance_map_growth);
  }
  if (config_.pose_covariance && !restored) {
    const std::optional<Mat6> S = NewestPoseCovariance(config_, registered, lidar.get(),
                                                       *estimator_, last_marginalization_.prior,
                                                       result->T_mr, &covariance_models_, &window_);
    result->has_pose_covariance = S.has_value();
    if (S) result->pose_covariance = *S;
  }
  calibration_.Report(estimator_->NewestKeys(), &window_, result);
}

void LioOdometry::Slide(ScanResult* result) {
  if (slid_) return;  // overlapped with the preprocessing (StartOverlappedStages)
  result->ms_marginalize += SlideWindow();
}

double LioOdometry::SlideWindow() {
  const auto t0 = std::chrono::steady_clock::now();
  while (estimator_->num_states() > config_.window_knots - 1) {
    final_trajectory_.SealOldest(estimator_.get(), imu_.origin_ns());
    last_marginalization_ = window_.Marginalize(estimator_->OldestKeys());
    ++num_marginalizations_;
    estimator_->DropOldest();
  }
  return MsSince(t0);
}

MarginalizationReport LioOdometry::ForgetCalibrationInformation() {
  std::vector<StateId> ids = calibration_.Ids(window_);
  if (ids.empty()) return {};
  // The gravity direction, refined with the extrinsic, was linearised in the same first seconds.
  if (window_.HasState(kGravityKey) && !window_.IsStateConstant(kGravityKey)) {
    ids.push_back(kGravityKey);
  }
  const MarginalizationReport report = window_.ForgetInformation(ids);
  // The window's one marginal prior (each slide folds the previous one in), which the pose
  // covariance reads, is on the calibration states (they connect to every knot): replaced.
  if (report.removed_residual_blocks > 0) last_marginalization_.prior = report.prior;
  return report;
}

void LioOdometry::RestartMap() {
  if (map_insertion_.valid()) map_insertion_.get();  // the newest scan's, on the second thread
  frontend_.map().Clear();
  if (map_points_inserted_) InsertMapPoints();
}

SE3 LioOdometry::CurrentExtrinsic() const {
  return window_.HasState(kExtrinsicKey) ? window_.Pose(kExtrinsicKey) : config_.T_imu_lidar;
}

void LioOdometry::InsertMapPoints() {
  const size_t before = frontend_.map().num_points();
  frontend_.UpdateMap(map_points_, map_position_);  // RemoveFar may also drop far voxels
  map_size_ = frontend_.map().num_points();
  map_points_kept_ = map_size_ > before ? map_size_ - before : 0;
}

void LioOdometry::StartMapInsertion() {
  map_insertion_ = std::async(std::launch::async, [this] {
    const auto t0 = std::chrono::steady_clock::now();
    InsertMapPoints();
    return MsSince(t0);
  });
}

std::future<std::pair<double, double>> LioOdometry::StartOverlappedStages() {
  slid_ = false;
  // Before the first Process nothing is inserted (Initialise inserts on the scan thread) and
  // nothing slides.
  if (!config_.overlap_stages || !initialised_) return {};
  // Process slides first thing (Initialise does not): done here beside the preprocessing, which
  // reads neither the map nor the window (its extrinsic was read before), after the previous
  // scan's map insertion on the same second thread (waited for there, not here).
  slid_ = true;
  std::future<double> insertion = std::move(map_insertion_);
  return std::async(std::launch::async, [this, insertion = std::move(insertion)]() mutable {
    const double ms_map = insertion.valid() ? insertion.get() : 0.0;
    return std::make_pair(ms_map, SlideWindow());
  });
}

void LioOdometry::ReportImuGap(double t_begin, double t_end, ScanResult* result) const {
  if (!uses_imu()) return;
  double max_gap = imu_.MaxGap(t_begin, t_end, config_.input_imu);
  if (config_.method != LioMethod::kImuInput) {
    for (int j = 0; j < config_.num_imus(); ++j) {
      max_gap = std::min(max_gap, imu_.MaxGap(t_begin, t_end, j));
    }
  }
  if (max_gap <= config_.max_imu_gap) return;
  std::ostringstream m;
  m << "IMU gap of " << max_gap << " s (limit " << config_.max_imu_gap
    << " s): " << estimator_->ImuGapRecovery();
  result->status = ScanStatus::kImuGap;
  result->message = m.str();
}

void LioOdometry::AnalyseDegeneracy(const RegistrationSummary& registered, const SE3& predicted,
                                    ScanResult* result) {
  const DegeneracyOptions& o = config_.degeneracy;
  if (!o.enabled || registered.lidar_blocks.empty()) return;
  const StateId pose = estimator_->NewestPoseKey();
  const Mat6 A = estimator_->NewestPoseTangentFromBody();
  DegeneracyReport& report = result->degeneracy;
  report = lio::AnalyseDegeneracy(PoseInformation(window_, registered.lidar_blocks, pose, A), o);
  if (report.directions.empty()) return;
  const Vec6& u = report.directions.front();
  report.prior_information = u.dot(OtherInformation(window_, registered.lidar_blocks, pose, A) * u);
  if (!without_imu_.active() || !o.remap) return;
  // No IMU measures the scan (lidar_only, or an IMU outage): keep the prediction along the
  // degenerate directions (solution remapping, degeneracy.h) and re-solve the other directions
  // with it. In an outage the estimate along them is otherwise the registration's drift (tuning
  // index 102, quad walk, 2 s outage: 9.4 m on the hdl32e).
  window_.AddResidualBlock(new PosePrior(predicted, RemapSqrtInformation(report, o, A)), nullptr,
                           {pose});
  const auto t0 = std::chrono::steady_clock::now();
  const ceres::Solver::Summary solved = window_.Solve();
  result->ms_solve += MsSince(t0);
  result->solver_iterations += static_cast<int>(solved.iterations.size());
  result->final_cost = solved.final_cost;
  report.remapped = true;
}

std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config) {
  return std::make_unique<LioOdometry>(config);
}

}  // namespace ctlio::lio
