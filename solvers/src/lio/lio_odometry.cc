#include "ctlio/solvers/lio/lio_odometry.h"

#include <ceres/covariance.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/degeneracy.h"
#include "ctlio/solvers/lio/gravity_alignment.h"
#include "ctlio/solvers/lio/input_checks.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

namespace {

const OdometryConfig& Validated(const OdometryConfig& config) {
  config.Validate();
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

double ThreadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Time order groups the points of one firing, whose interpolated pose the pipelines share. A
// sweep usually arrives in firing order already: then the (allocating) sort is skipped.
void SortByTime(std::vector<TimedPoint>* points) {
  const auto by_time = [](const TimedPoint& a, const TimedPoint& b) { return a.time < b.time; };
  if (!std::is_sorted(points->begin(), points->end(), by_time)) {
    std::stable_sort(points->begin(), points->end(), by_time);
  }
}

// Appends a note to the scan's message ("; "-separated).
void AddNote(ScanResult* result, const std::string& note) {
  result->message += (result->message.empty() ? "" : "; ") + note;
}

// How CalibrationStates() splits: the clock offsets, then the extrinsic when estimated.
struct CalibrationShape {
  int offsets = 0;
  bool extrinsic = false;
};
CalibrationShape ShapeOf(const std::vector<StateId>& states) {
  CalibrationShape shape;
  shape.extrinsic = !states.empty() && states.back() == kExtrinsicKey;
  shape.offsets = static_cast<int>(states.size()) - (shape.extrinsic ? 1 : 0);
  return shape;
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
      estimator_(MakeEstimator(config_, imu_)) {}

LioOdometry::~LioOdometry() = default;

std::vector<std::pair<int64_t, SE3>> LioOdometry::SampleNewestInterval(double rate_hz) const {
  if (replay_ != nullptr) return replay_->SampleNewestInterval(rate_hz);
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

FinalTrajectory::Samples LioOdometry::TakeFinalTrajectory() {
  if (replay_ != nullptr) return replay_->TakeFinalTrajectory();
  return final_trajectory_.Take();
}

FinalTrajectory::Samples LioOdometry::FinalTrajectoryTail() const {
  if (replay_ != nullptr) return replay_->FinalTrajectoryTail();
  if (!initialised_) return {};
  return final_trajectory_.Tail(*estimator_, imu_.origin_ns());
}

bool LioOdometry::AddImu(const ImuSample& sample) {
  if (replay_ != nullptr) return replay_->AddImu(sample);
  if (sample.imu >= config_.num_imus()) {
    throw std::invalid_argument("LioOdometry::AddImu: sample of IMU " + std::to_string(sample.imu) +
                                ", the config declares " + std::to_string(config_.num_imus()) +
                                " (imus:)");
  }
  // Kept as given, rejected or not: the replay's own buffer applies the same gates again.
  if (KeepsWarmup()) warmup_imu_.push_back(sample);
  return imu_.AddImu(sample);
}

ScanResult LioOdometry::AddScan(const LidarScan& input) {
  if (replay_ != nullptr) return replay_->AddScan(input);
  CheckScan(input);
  if (KeepsWarmup()) warmup_scans_.emplace_back(input, warmup_imu_.size());
  ScanResult result = RunScan(input);
  if (KeepsWarmup()) MaybeReplayWarmup(&result);
  return result;
}

void LioOdometry::MaybeReplayWarmup(ScanResult* result) {
  const double span = 1e-9 * static_cast<double>(warmup_scans_.back().first.end_ns -
                                                 warmup_scans_.front().first.begin_ns);
  const double needed = config_.calibration.warmup_replay_s;
  if (span < needed) return;
  warmup_done_ = true;
  if (!initialised_ || result->status == ScanStatus::kFailed) {
    if (span < 2.0 * needed) {
      warmup_done_ = false;  // wait for an estimated scan
      return;
    }
    AddNote(result, "calibration warm-up not replayed: no estimate after " + std::to_string(span) +
                        " s (calibration.warmup_replay_s)");
    warmup_scans_ = {};
    warmup_imu_ = {};
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMs();
  // Each pass starts from the estimates the one before ended with (the live ones for the first).
  const int passes = config_.calibration.warmup_replay_passes;
  std::unique_ptr<LioOdometry> replay;
  ScanResult replayed;
  ScanResult::CalibrationEstimate start_values = result->calibration;
  for (int pass = 0; pass < passes; ++pass) {
    const bool last = pass == passes - 1;
    OdometryConfig replay_config = ReplayConfig(start_values);
    // The caller re-reads every replayed result of the span (ScanResult::revised_scans).
    if (replay_config.kept_results > 0) {
      replay_config.kept_results = std::max(replay_config.kept_results, warmup_scans_.size());
    }
    const bool hold = last && config_.calibration.warmup_replay_hold;
    if (hold) replay_config.calibration.hold_gravity = true;
    const bool freeze = last && config_.calibration.warmup_replay_freeze;
    if (freeze) {
      // ReplayConfig has put the values into the configuration: known values from here on.
      replay_config.calibration.estimate_time_offset = false;
      replay_config.calibration.estimate_extrinsic = false;
    }
    replay = std::make_unique<LioOdometry>(replay_config);
    replay->SampleFinalTrajectory(final_trajectory_.rate());
    if (freeze) {
      replay->frozen_calibration_ = Frozen(start_values, replay_config);
    }
    if (hold) {
      // The replay's clock starts at the first kept scan's begin, so its scans end within span.
      replay->hold_calibration_until_s_ = span;
      replay->hold_mask_ = start_values.unobservable;
      replay->hold_mask_.flip();  // the observable coordinates; empty (no check): all
    }
    size_t next_imu = 0;
    for (const auto& [scan, imu_before] : warmup_scans_) {
      for (; next_imu < imu_before; ++next_imu) replay->AddImu(warmup_imu_[next_imu]);
      replayed = replay->AddScan(scan);
    }
    for (; next_imu < warmup_imu_.size(); ++next_imu) replay->AddImu(warmup_imu_[next_imu]);
    // A pass that ends without an estimate is the one that carries on: nothing to start from.
    if (replayed.status == ScanStatus::kFailed || !replay->initialised()) break;
    start_values = replayed.calibration;
  }
  // This call's cost is the live scan's and the whole replay's.
  replayed.revised_scans = static_cast<int>(warmup_scans_.size()) - 1;
  replayed.milliseconds = result->milliseconds + MsSince(start);
  replayed.cpu_ms = result->cpu_ms + ThreadCpuMs() - cpu_start;
  std::ostringstream note;
  note << "calibration warm-up replayed: " << warmup_scans_.size() << " scans over " << span
       << " s processed again from the estimates after this scan";
  if (passes > 1) note << " (" << passes << " passes, each from the previous one's estimates)";
  if (config_.calibration.warmup_replay_hold) note << ", the calibration held over the span";
  if (config_.calibration.warmup_replay_freeze) {
    note << ", the calibration frozen at the values the "
         << (passes > 1 ? "pass before" : "live run") << " ended with";
  }
  AddNote(&replayed, note.str());
  replay->results_.back() = replayed;
  // The caller has re-read the span's results with this one: the configured bound holds again.
  replay->config_.kept_results = config_.kept_results;
  warmup_results_ = std::move(results_);
  results_ = {};
  warmup_scans_ = {};
  warmup_imu_ = {};
  replay_ = std::move(replay);
  *result = replayed;
}

ScanResult::CalibrationEstimate LioOdometry::Frozen(const ScanResult::CalibrationEstimate& estimate,
                                                    const OdometryConfig& config) {
  // The values the pipeline runs with (ReplayConfig's: an unobservable coordinate is back at its
  // configured value), with the estimate's σ and observability.
  ScanResult::CalibrationEstimate frozen = estimate;
  for (size_t j = 0; j < frozen.time_offset_s.size(); ++j) {
    frozen.time_offset_s[j] = config.calibration.TimeOffset(static_cast<int>(j));
  }
  if (frozen.has_extrinsic) {
    frozen.T_imu_lidar = config.T_imu_lidar;
  }
  frozen.held.assign(frozen.time_offset_s.size() + (frozen.has_extrinsic ? 6 : 0), true);
  return frozen;
}

OdometryConfig LioOdometry::ReplayConfig(const ScanResult::CalibrationEstimate& estimate) const {
  // The estimates become the replay's start values and prior means; the configured σ stays (the
  // replay uses the same data again, so it must not also be told it is sure of them). A
  // coordinate the observability check left unobservable starts from its configured value
  // instead: its estimate is drift, and passes started from drift would add it up.
  OdometryConfig replay = config_;
  CalibrationOptions& cal = replay.calibration;
  cal.warmup_replay_s = 0.0;  // the replay does not replay
  cal.warmup_replay_passes = 1;
  cal.warmup_replay_hold = false;
  cal.warmup_replay_freeze = false;
  const std::vector<bool>& unobservable = estimate.unobservable;
  auto observable = [&](size_t i) { return i >= unobservable.size() || !unobservable[i]; };
  const size_t offsets = estimate.time_offset_s.size();
  if (cal.estimate_time_offset && offsets > 0) {
    cal.time_offset_s.resize(offsets);
    for (size_t j = 0; j < offsets; ++j) {
      cal.time_offset_s[j] = observable(j) ? estimate.time_offset_s[j]
                                           : config_.calibration.TimeOffset(static_cast<int>(j));
    }
  }
  if (cal.estimate_extrinsic && estimate.has_extrinsic) {
    // The coordinates of the report (calibration.csv): T = Exp([ρ; φ])·T_configured.
    Vec6 xi = (estimate.T_imu_lidar * config_.T_imu_lidar.Inverse()).Log();
    for (size_t k = 0; k < 6; ++k) {
      if (!observable(offsets + k)) xi[static_cast<Eigen::Index>(k)] = 0.0;
    }
    replay.T_imu_lidar = SE3::Exp(xi) * config_.T_imu_lidar;
  }
  return replay;
}

ScanResult LioOdometry::RunScan(const LidarScan& input) {
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
  const LidarScan& scan = DropPointsOutsideInterval(input, &trimmed, &dropped_note);
  result.points_dropped = static_cast<int>(input.points.size() - scan.points.size());
  const SE3 T_robot_lidar = CurrentExtrinsic();
  std::future<std::pair<double, double>> overlapped = StartOverlappedStages();
  const PreparedScan& prepared = PrepareScan(scan, T_robot_lidar);
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
  // After a frozen warm-up replay: the values this pipeline runs with, as the estimate.
  if (frozen_calibration_) {
    result.calibration = *frozen_calibration_;
  }
  imu_.Trim(imu_.Seconds(last_scan_end_ns_) - 0.5);
  result.milliseconds = MsSince(start);
  result.cpu_ms = ThreadCpuMs() - cpu_start;
  results_.push_back(result);
  // A pending warm-up replay replaces every result of its span: those stay until it has run.
  if (config_.kept_results > 0 && !KeepsWarmup()) {
    while (results_.size() > config_.kept_results) results_.pop_front();
  }
  return result;
}

const LidarScan& LioOdometry::DropPointsOutsideInterval(const LidarScan& scan, LidarScan* trimmed,
                                                        std::string* note) const {
  const int64_t tolerance = std::llround(config_.input.scan_time_tolerance * 1e9);
  const int64_t begin = initialised_ ? last_scan_end_ns_ : scan.begin_ns;
  const int64_t lo = begin - tolerance, hi = scan.end_ns + tolerance;
  const auto outside = [&](int64_t t) { return t < lo || t > hi; };
  if (std::none_of(scan.times_ns.begin(), scan.times_ns.end(), outside)) return scan;
  *trimmed = scan;
  const size_t dropped = DropPointsOutside(lo, hi, trimmed);
  std::ostringstream m;
  m << std::fixed << std::setprecision(9) << "dropped " << dropped << " of " << scan.points.size()
    << " points timed outside [" << 1e-9 * double(begin) << ", " << 1e-9 * double(scan.end_ns)
    << "] s by more than input.scan_time_tolerance " << config_.input.scan_time_tolerance << " s";
  *note = m.str();
  return *trimmed;
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

  const SE3 predicted = window_.Pose(estimator_->NewestPoseKey());
  const std::unique_ptr<LidarTerm> lidar = estimator_->MakeLidarTerm(scan, &window_);
  HoldCalibration(scan.t_end, result);
  const RegistrationSummary registered =
      registration_.Register(frontend_.map(), lidar.get(), &window_);
  ReleaseCalibration();
  if (!registered.degenerate) AnalyseDegeneracy(registered, predicted, result);
  result->rounds = registered.rounds;
  result->solver_iterations = registered.solver_iterations;
  result->associations = registered.associations;
  result->final_cost = registered.final_cost;
  result->ms_associate = registered.ms_associate;
  result->ms_solve = registered.ms_solve;

  const auto t_map = std::chrono::steady_clock::now();
  if (EstimatePlausible(result)) {
    estimator_->MapPoints(scan, &map_points_);
    map_position_ = estimator_->NewestPose().translation();
    map_points_inserted_ = true;
    if (config_.overlap_stages) {
      // Inserted on a second thread from now on: in real time, while the robot waits for the
      // next sweep; back to back, beside the rest of this scan and the next one's preprocessing.
      // Joined before anything reads the map (StartOverlappedStages' task, or RunScan).
      StartMapInsertion();
    } else {
      frontend_.UpdateMap(map_points_, map_position_);
    }
  }
  if (registered.degenerate) ReportDegenerate(result);
  if (!uses_imu() && result->degeneracy.num_degenerate() > 0) ReportDegenerateDirections(result);
  result->ms_map += MsSince(t_map);
  estimator_->Report(result);
  if (config_.pose_covariance) ReportPoseCovariance(result);
  if (config_.calibration.any()) {
    AssessCalibrationObservability(result);
    ReportCalibrationCovariance(result);
  }
}

void LioOdometry::AssessCalibrationObservability(ScanResult* result) {
  if (!StartObservability()) return;
  // The newest interval's factors: every residual block on a state of the newest knot.
  std::vector<ceres::ResidualBlockId> newest;
  std::unordered_set<ceres::ResidualBlockId> seen;
  for (const StateId id : estimator_->NewestKeys()) {
    for (const ceres::ResidualBlockId r : window_.ResidualBlocksOf(id)) {
      if (seen.insert(r).second) newest.push_back(r);
    }
  }
  observability_->AddScan(MarginalInformation(window_, newest, CalibrationStates()));
  const Eigen::VectorXd& nu = observability_->whitened_information();
  result->calibration.observability.assign(nu.data(), nu.data() + nu.size());
  result->calibration.unobservable = observability_->Unobservable();
}

std::vector<StateId> LioOdometry::CalibrationStates() const {
  std::vector<StateId> states;
  for (int j = 0; j < config_.num_imus(); ++j) {
    if (window_.HasState(TimeOffsetKey(j))) states.push_back(TimeOffsetKey(j));
  }
  if (window_.HasState(kExtrinsicKey)) states.push_back(kExtrinsicKey);
  return states;
}

bool LioOdometry::StartObservability() {
  if (observability_ != nullptr) return true;
  if (config_.calibration.observability_horizon_scans == 0) return false;
  const std::vector<StateId> states = CalibrationStates();
  if (states.empty()) return false;
  const CalibrationShape shape = ShapeOf(states);
  observability_ = std::make_unique<CalibrationObservability>(config_.calibration, shape.offsets,
                                                              shape.extrinsic);
  return true;
}

void LioOdometry::HoldCalibration(double t_end, ScanResult* result) {
  const CalibrationOptions& cal = config_.calibration;
  if (!cal.any()) return;
  std::vector<bool> hold;
  Eigen::VectorXd sigma;
  if (t_end <= hold_calibration_until_s_ + 1e-6) {
    // The last pass of a warm-up replay over its span (calibration.warmup_replay_hold).
    const CalibrationShape shape = ShapeOf(CalibrationStates());
    const std::vector<double> prior = cal.PriorSigmas(shape.offsets, shape.extrinsic);
    hold = hold_mask_.empty() ? std::vector<bool>(prior.size(), true) : hold_mask_;
    sigma =
        Eigen::Map<const Eigen::VectorXd>(prior.data(), static_cast<Eigen::Index>(prior.size()));
  } else if (cal.hold_unobservable && StartObservability()) {
    // Before any assessment everything is unobservable (nothing measured yet): held too.
    hold = observability_->Unobservable();
    sigma = observability_->prior_sigma();
  } else {
    return;
  }
  result->calibration.held = hold;
  // A prior at the current value along each held coordinate, σ_hold = σ_prior/√w: the
  // solve moves it by a negligible amount; removed again before anything else reads the window.
  const double w = std::sqrt(cal.hold_information);
  int i = 0;
  for (const StateId id : CalibrationStates()) {
    if (id == kExtrinsicKey) {
      Mat6 sqrt_information = Mat6::Zero();
      for (int a = 0; a < 6; ++a, ++i) {
        if (hold[static_cast<size_t>(i)]) sqrt_information(a, a) = w / sigma[i];
      }
      if (sqrt_information.isZero()) continue;
      holds_.push_back(window_.AddResidualBlock(
          new PosePrior(window_.Pose(kExtrinsicKey), sqrt_information), nullptr, {id}));
      continue;
    }
    if (hold[static_cast<size_t>(i)]) {
      holds_.push_back(window_.AddResidualBlock(
          new EuclideanPrior<1>(Eigen::Matrix<double, 1, 1>(window_.State(id)[0]),
                                Eigen::Matrix<double, 1, 1>(w / sigma[i])),
          nullptr, {id}));
    }
    ++i;
  }
}

void LioOdometry::ReleaseCalibration() {
  for (const ceres::ResidualBlockId r : holds_) window_.RemoveResidualBlock(r);
  holds_.clear();
}

void LioOdometry::ReportPoseCovariance(ScanResult* result) {
  double* pose = window_.State(estimator_->NewestPoseKey());
  // Sparse QR of the window's Jacobian (the default); a rank-deficient window gives no
  // covariance (the scan then has none) rather than a pseudo-inverse.
  ceres::Covariance covariance(ceres::Covariance::Options{});
  const std::vector<std::pair<const double*, const double*>> blocks = {{pose, pose}};
  if (!covariance.Compute(blocks, &window_.problem())) return;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
  if (!covariance.GetCovarianceBlockInTangentSpace(pose, pose, block.data())) return;
  // The block's tangent δ_state = A·δ_body (T_mr ← T_mr·Exp(δ_body)), and T_mr·Exp(δ_body) =
  // Exp(Ad(T_mr)·δ_body)·T_mr: ε = Ad(T_mr)·A⁻¹·δ_state (the GP knots' T_rm: A = −I; the
  // baseline's T_wb: A = Ad(T_wb), so ε = δ_state).
  const Mat6 M = result->T_mr.Adjoint() * estimator_->NewestPoseTangentFromBody().inverse();
  result->pose_covariance = M * Mat6(block) * M.transpose();
  result->has_pose_covariance = true;
}

void LioOdometry::ReportCalibrationCovariance(ScanResult* result) {
  // The extrinsic's tangent is PoseManifold's left [ρ; φ].
  const std::vector<StateId> states = CalibrationStates();
  if (states.empty()) return;
  const auto [offsets, extrinsic] = ShapeOf(states);
  // Their marginal covariance is the inverse of their marginal information: every residual of
  // the window linearised once, every other state marginalised by the Schur complement
  // (degeneracy.h, as for the observability check). Its pseudo-inverse drops the null direction
  // that C_mi has when it is refined with the extrinsic (the yaw about gravity): the value of
  // the window's pseudo-inverse (ceres::Covariance, dense SVD, null space dropped, which the
  // test compares with) at a quarter of the instructions, since that SVD is of the whole
  // ~1000-row Jacobian.
  std::vector<ceres::ResidualBlockId> residuals;
  window_.problem().GetResidualBlocks(&residuals);
  const Eigen::MatrixXd information = MarginalInformation(window_, residuals, states);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  const bool ok = eig.info() == Eigen::Success && eig.eigenvalues().minCoeff() > 0.0;
  Eigen::MatrixXd covariance;
  if (ok) {
    covariance = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
                 eig.eigenvectors().transpose();
  }
  auto& cal = result->calibration;
  cal.time_offset_sigma_s.clear();
  for (int j = 0; j < offsets; ++j) {
    cal.time_offset_sigma_s.push_back(ok ? std::sqrt(covariance(j, j)) : std::nan(""));
  }
  if (extrinsic && ok) {
    cal.extrinsic_sigma = covariance.diagonal().tail<6>().cwiseMax(0.0).cwiseSqrt();
  }
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

void LioOdometry::CheckScan(const LidarScan& scan) const {
  if (scan.points.size() != scan.times_ns.size()) {
    throw std::invalid_argument("LioOdometry::AddScan: scan ending at " +
                                std::to_string(scan.end_ns) + " ns has " +
                                std::to_string(scan.points.size()) + " points but " +
                                std::to_string(scan.times_ns.size()) + " times");
  }
  if (scan.end_ns <= scan.begin_ns) {
    throw std::invalid_argument("LioOdometry::AddScan: scan end " + std::to_string(scan.end_ns) +
                                " ns is not after its begin " + std::to_string(scan.begin_ns));
  }
  if (have_origin_ && scan.end_ns <= last_scan_end_ns_) {
    throw std::invalid_argument(
        "LioOdometry::AddScan: scan ending at " + std::to_string(scan.end_ns) +
        " ns is not after the previous one (" + std::to_string(last_scan_end_ns_) + " ns)");
  }
}

SE3 LioOdometry::CurrentExtrinsic() const {
  return window_.HasState(kExtrinsicKey) ? window_.Pose(kExtrinsicKey) : config_.T_imu_lidar;
}

void LioOdometry::StartMapInsertion() {
  map_insertion_ = std::async(std::launch::async, [this] {
    const auto t0 = std::chrono::steady_clock::now();
    frontend_.UpdateMap(map_points_, map_position_);
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

const PreparedScan& LioOdometry::PrepareScan(const LidarScan& scan, const SE3& T_robot_lidar) {
  const double t_prev =
      initialised_ ? imu_.Seconds(last_scan_end_ns_) : imu_.Seconds(scan.begin_ns);
  PreparedScan& prepared = prepared_;
  prepared.t_begin = imu_.Seconds(scan.begin_ns);
  prepared.t_end = imu_.Seconds(scan.end_ns);
  prepared.end_ns = scan.end_ns;
  // The configured extrinsic, or with online calibration its current estimate (the lidar
  // residuals recover the lidar-frame points through prepared.T_robot_lidar).
  prepared.T_robot_lidar = T_robot_lidar;
  // Range gate and voxel subsampling in the lidar frame (one pass, no copy of the up to 230 000
  // raw returns of a 128-beam sweep), then on the survivors in the robot frame, and the
  // keypoints: one stream, no intermediate copies (LidarFrontend::SelectSweep).
  thread_local SweepSelection selection;
  // With the overlap the second core runs the previous scan's map insertion and the
  // marginalisation meanwhile (StartOverlappedStages): a second range-gate thread would only
  // contend with them for the two cores (docs/experiments/latency.md: preprocessing 6.4 against 4.7
  // ms).
  frontend_.SelectSweep(scan.points, prepared.T_robot_lidar, &selection,
                        config_.overlap_stages ? 1 : config_.frontend.threads);
  prepared.points.resize(selection.indices.size());
  for (size_t j = 0; j < selection.indices.size(); ++j) {
    TimedPoint& p = prepared.points[j];
    p.point = selection.points_robot[j];
    // Points are registered between the previous knot and this one; a time outside by less than
    // input.scan_time_tolerance (clock jitter of the driver; the rest was dropped and counted in
    // DropPointsOutsideInterval) is clamped onto the interval rather than extrapolated. Finite,
    // so Preprocess's time check (RangeGate) would keep every point.
    p.time = std::clamp(imu_.Seconds(scan.times_ns[selection.indices[j]]), t_prev, prepared.t_end);
  }
  prepared.keypoints.clear();
  prepared.keypoints.reserve(selection.keypoints.size());
  for (const size_t j : selection.keypoints) prepared.keypoints.push_back(prepared.points[j]);
  SortByTime(&prepared.points);
  SortByTime(&prepared.keypoints);
  return prepared;
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

bool LioOdometry::EstimatePlausible(ScanResult* result) const {
  const SE3 T_mr = estimator_->NewestPose();
  const double jump = (T_mr.translation() - estimator_->PreviousPose().translation()).norm();
  if (T_mr.translation().allFinite() && jump <= config_.max_scan_translation) return true;
  // Do not pollute the map with a diverged pose; report it.
  std::ostringstream m;
  m << "pose jumped " << jump << " m in one scan (limit " << config_.max_scan_translation
    << " m): estimate diverged";
  result->status = ScanStatus::kFailed;
  result->message = m.str();
  return false;
}

void LioOdometry::ReportDegenerate(ScanResult* result) const {
  if (result->status != ScanStatus::kOk) return;
  result->status = ScanStatus::kDegenerate;
  result->message = "only " + std::to_string(result->associations) + " plane associations (need " +
                    std::to_string(config_.min_associations) +
                    "): lidar term dropped for this scan, the prior" +
                    (uses_imu() ? " and the IMU carry" : " carries") + " the state";
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
  if (uses_imu() || !o.remap) return;
  // lidar_only: keep the constant-velocity prediction along the degenerate directions (solution
  // remapping, degeneracy.h) and re-solve the other directions with it.
  window_.AddResidualBlock(new PosePrior(predicted, RemapSqrtInformation(report, o, A)), nullptr,
                           {pose});
  const auto t0 = std::chrono::steady_clock::now();
  const ceres::Solver::Summary solved = window_.Solve();
  result->ms_solve += MsSince(t0);
  result->solver_iterations += static_cast<int>(solved.iterations.size());
  result->final_cost = solved.final_cost;
  report.remapped = true;
}

void LioOdometry::ReportDegenerateDirections(ScanResult* result) const {
  if (result->status != ScanStatus::kOk) return;
  result->status = ScanStatus::kDegenerate;
  result->message = std::to_string(result->degeneracy.num_degenerate()) +
                    " degenerate direction(s) of the lidar term (least constrained " +
                    result->degeneracy.DirectionString() + " in the body frame): no IMU to carry " +
                    (result->degeneracy.remapped
                         ? "them, the constant-velocity prediction is kept along them (solution "
                           "remapping)"
                         : "them (degeneracy.remap off: the estimate along them is the lidar's)");
}

std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config) {
  return std::make_unique<LioOdometry>(config);
}

}  // namespace ctlio::lio
