#include "ctlio/solvers/lio/calibrating_odometry.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <sstream>
#include <string>

#include "scan_clock.h"

namespace ctlio::lio {

using internal::AddNote;
using internal::MsSince;
using internal::ThreadCpuMs;

namespace {

const OdometryConfig& Validated(const OdometryConfig& config) {
  config.Validate();
  return config;
}

// `config` as one pass: no replay of its own.
OdometryConfig SinglePass(OdometryConfig config) {
  CalibrationOptions& cal = config.calibration;
  cal.warmup_replay_s = 0.0;
  cal.warmup_replay_passes = 1;
  cal.warmup_replay_hold = false;
  cal.warmup_replay_freeze = false;
  return config;
}

// A pipeline inside this one: the history is CalibratingOdometry's, so it keeps one result.
std::unique_ptr<LioOdometry> MakePipeline(OdometryConfig config, double trajectory_rate_hz) {
  config.kept_results = 1;
  auto pipeline = std::make_unique<LioOdometry>(config);
  pipeline->SampleFinalTrajectory(trajectory_rate_hz);
  return pipeline;
}

}  // namespace

OdometryConfig ReplayConfig(const OdometryConfig& config,
                            const ScanResult::CalibrationEstimate& estimate) {
  // The estimates become the replay's start values and prior means; the configured σ stays (the
  // replay uses the same data again, so it must not also be told it is sure of them). A
  // coordinate the observability check left unobservable starts from its configured value
  // instead: its estimate is drift, and passes started from drift would add it up.
  OdometryConfig replay = SinglePass(config);
  CalibrationOptions& cal = replay.calibration;
  const std::vector<bool>& unobservable = estimate.unobservable;
  auto observable = [&](size_t i) { return i >= unobservable.size() || !unobservable[i]; };
  const size_t offsets = estimate.time_offset_s.size();
  if (cal.estimate_time_offset && offsets > 0) {
    cal.time_offset_s.resize(offsets);
    for (size_t j = 0; j < offsets; ++j) {
      cal.time_offset_s[j] = observable(j) ? estimate.time_offset_s[j]
                                           : config.calibration.TimeOffset(static_cast<int>(j));
    }
  }
  if (cal.estimate_extrinsic && estimate.has_extrinsic) {
    // The coordinates of the report (calibration.csv): T = Exp([ρ; φ])·T_configured.
    Vec6 xi = (estimate.T_imu_lidar * config.T_imu_lidar.Inverse()).Log();
    for (size_t k = 0; k < 6; ++k) {
      if (!observable(offsets + k)) xi[static_cast<Eigen::Index>(k)] = 0.0;
    }
    replay.T_imu_lidar = SE3::Exp(xi) * config.T_imu_lidar;
  }
  return replay;
}

ScanResult::CalibrationEstimate FrozenCalibration(const ScanResult::CalibrationEstimate& estimate,
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

CalibratingOdometry::CalibratingOdometry(const OdometryConfig& config)
    : config_(Validated(config)),
      pipeline_(MakePipeline(SinglePass(config), 0.0)),
      keeping_(config.calibration.replays_warmup()) {}

CalibratingOdometry::~CalibratingOdometry() = default;

void CalibratingOdometry::SampleFinalTrajectory(double rate_hz) {
  trajectory_rate_hz_ = rate_hz;
  pipeline_->SampleFinalTrajectory(rate_hz);
}

bool CalibratingOdometry::AddImu(const ImuSample& sample) {
  const bool added = pipeline_->AddImu(sample);
  // Kept as given, rejected or not: the replay's own buffer applies the same gates again. A
  // sample the pipeline threw on (out of order, an undeclared IMU) is not kept.
  if (keeping_) warmup_imu_.push_back(sample);
  return added;
}

ScanResult CalibratingOdometry::AddScan(const LidarScan& scan) {
  ScanResult result = pipeline_->AddScan(scan);  // throws on a bad scan: nothing kept then
  if (frozen_) result.calibration = *frozen_;
  const bool keeping = keeping_;
  if (keeping) warmup_scans_.emplace_back(scan, warmup_imu_.size());
  // A pending replay replaces every result of its span: those stay until it has run.
  Record(result, !keeping);
  if (keeping) MaybeReplay(&result);
  return result;
}

void CalibratingOdometry::Record(const ScanResult& result, bool bounded) {
  results_.push_back(result);
  if (config_.kept_results > 0 && bounded) {
    while (results_.size() > config_.kept_results) results_.pop_front();
  }
}

void CalibratingOdometry::MaybeReplay(ScanResult* result) {
  const double span = 1e-9 * static_cast<double>(warmup_scans_.back().first.end_ns -
                                                 warmup_scans_.front().first.begin_ns);
  const double needed = config_.calibration.warmup_replay_s;
  if (span < needed) return;
  if (pipeline_->initialised() && result->status != ScanStatus::kFailed) {
    Replay(span, result);
    return;
  }
  if (span < 2.0 * needed) return;  // wait for an estimated scan
  keeping_ = false;
  AddNote(result, "calibration warm-up not replayed: no estimate after " + std::to_string(span) +
                      " s (calibration.warmup_replay_s)");
  warmup_scans_ = {};
  warmup_imu_ = {};
}

void CalibratingOdometry::Replay(double span, ScanResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMs();
  const CalibrationOptions& options = config_.calibration;
  // Each pass starts from the estimates the one before ended with (the live ones for the first).
  const int passes = options.warmup_replay_passes;
  std::unique_ptr<LioOdometry> replay;
  OdometryConfig replay_config;
  std::optional<ScanResult::CalibrationEstimate> frozen;
  std::deque<ScanResult> replayed_results;
  ScanResult replayed;
  ScanResult::CalibrationEstimate start_values = result->calibration;
  for (int pass = 0; pass < passes; ++pass) {
    const bool last = pass == passes - 1;
    replay_config = ReplayConfig(config_, start_values);
    const bool hold = last && options.warmup_replay_hold;
    if (hold) replay_config.calibration.hold_gravity = true;
    frozen.reset();
    if (last && options.warmup_replay_freeze) {
      // ReplayConfig has put the values into the configuration: known values from here on.
      replay_config.calibration.estimate_time_offset = false;
      replay_config.calibration.estimate_extrinsic = false;
      frozen = FrozenCalibration(start_values, replay_config);
    }
    replay = MakePipeline(replay_config, trajectory_rate_hz_);
    if (hold) {
      // The replay's clock starts at the first kept scan's begin, so its scans end within span.
      std::vector<bool> observable = start_values.unobservable;
      observable.flip();  // empty (no check): all
      replay->HoldCalibrationUntil(span, std::move(observable));
    }
    replayed_results.clear();
    size_t next_imu = 0;
    for (const auto& [scan, imu_before] : warmup_scans_) {
      for (; next_imu < imu_before; ++next_imu) replay->AddImu(warmup_imu_[next_imu]);
      replayed = replay->AddScan(scan);
      if (frozen) replayed.calibration = *frozen;
      replayed_results.push_back(replayed);
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
  if (options.warmup_replay_hold) note << ", the calibration held over the span";
  if (options.warmup_replay_freeze) {
    note << ", the calibration frozen at the values the "
         << (passes > 1 ? "pass before" : "live run") << " ended with";
  }
  AddNote(&replayed, note.str());
  replayed_results.back() = replayed;
  // The swap: the replayed pipeline, its config (the caller's result bound), its results.
  const size_t kept = config_.kept_results;
  config_ = replay_config;
  config_.kept_results = kept;
  warmup_results_ = std::move(results_);
  results_ = std::move(replayed_results);
  warmup_scans_ = {};
  warmup_imu_ = {};
  keeping_ = false;
  frozen_ = frozen;
  pipeline_ = std::move(replay);
  *result = replayed;
}

}  // namespace ctlio::lio
