#include "ctlio/solvers/lio/calibrating_odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>
#include <stdexcept>
#include <string>

#include "scan_clock.h"
#include "warmup_replay_worker.h"

namespace ctlio::lio {

using internal::AddNote;
using internal::MsSince;

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
  cal.warmup_forget_s = 0.0;
  cal.warmup_forget_restart_map = false;
  return config;
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

CalibratingOdometry::CalibratingOdometry(const OdometryConfig& config, ReplaySchedule schedule)
    : config_(Validated(config)),
      schedule_(schedule),
      pipeline_(internal::MakeReplayPipeline(SinglePass(config), 0.0)),
      keeping_(config.calibration.replays_warmup()),
      forgetting_(config.calibration.forgets_warmup()) {
  if (!(schedule_.adopt_after_s >= 0.0)) {
    throw std::invalid_argument("CalibratingOdometry: ReplaySchedule::adopt_after_s must be >= 0");
  }
}

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
  if (background_) background_->Push(sample);
  return added;
}

ScanResult CalibratingOdometry::AddScan(const LidarScan& scan) {
  ScanResult result = pipeline_->AddScan(scan);  // throws on a bad scan: nothing kept then
  if (frozen_) result.calibration = *frozen_;
  if (background_) {
    background_->Push(scan);
    ++background_scans_;
  }
  if (keeping_) warmup_scans_.emplace_back(scan, warmup_imu_.size());
  // A pending replay replaces every result of its span (and of the catch-up): those stay until
  // it is adopted.
  Record(result, !keeping_ && !background_);
  if (keeping_) MaybeReplay(&result);
  if (forgetting_) MaybeForget(scan, &result);
  if (background_ && scan.end_ns >= adopt_ns_) AdoptBackground(&result);
  return result;
}

std::optional<ScanResult> CalibratingOdometry::Finish() {
  if (!background_) return std::nullopt;
  ScanResult result = results_.back();
  AdoptBackground(&result);
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

void CalibratingOdometry::MaybeForget(const LidarScan& scan, ScanResult* result) {
  if (first_begin_ns_ < 0) first_begin_ns_ = scan.begin_ns;
  const double span = 1e-9 * static_cast<double>(scan.end_ns - first_begin_ns_);
  if (span < config_.calibration.warmup_forget_s || !pipeline_->initialised() ||
      result->status == ScanStatus::kFailed) {
    return;
  }
  forgetting_ = false;
  const MarginalizationReport forgot = pipeline_->ForgetCalibrationInformation();
  std::ostringstream note;
  note << "calibration warm-up forgotten after " << span << " s: " << forgot.removed_residual_blocks
       << " marginal prior(s) replaced by their marginal over the " << forgot.kept.size()
       << " other states (calibration.warmup_forget_s)";
  if (config_.calibration.warmup_forget_restart_map) {
    pipeline_->RestartMap();
    note << "; the map restarted from this scan";
  }
  AddNote(result, note.str());
  results_.back().message = result->message;
}

void CalibratingOdometry::Replay(double span, ScanResult* result) {
  const CalibrationOptions& options = config_.calibration;
  internal::WarmupSpan kept{std::move(warmup_imu_), std::move(warmup_scans_)};
  warmup_scans_ = {};
  warmup_imu_ = {};
  keeping_ = false;
  std::ostringstream note;
  note << "calibration warm-up replayed: " << kept.scans.size() << " scans over " << span
       << " s processed again from the estimates after "
       << (schedule_.background ? "scan " + std::to_string(results_.size() - 1) : "this scan");
  const int passes = options.warmup_replay_passes;
  if (passes > 1) note << " (" << passes << " passes, each from the previous one's estimates)";
  if (options.warmup_replay_hold) note << ", the calibration held over the span";
  if (options.warmup_replay_freeze) {
    note << ", the calibration frozen at the values the "
         << (passes > 1 ? "pass before" : "live run") << " ended with";
  }
  background_scans_ = kept.scans.size() * static_cast<size_t>(passes);
  if (schedule_.background) {
    adopt_ns_ = kept.scans.back().first.end_ns +
                static_cast<int64_t>(std::llround(1e9 * schedule_.adopt_after_s));
    note << ", on a second thread, adopted with the first scan ending " << schedule_.adopt_after_s
         << " s later (or at the end of the input)";
    replay_note_ = note.str();
    background_ = std::make_unique<internal::BackgroundReplay>(
        config_, trajectory_rate_hz_, std::move(kept), span, result->calibration);
    AddNote(result, "calibration warm-up replay started on a second thread");
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  internal::ReplayedPipeline replayed =
      internal::ReplayWarmup(config_, trajectory_rate_hz_, kept, span, result->calibration);
  Adopt(std::move(replayed), MsSince(start), note.str(), result);
}

void CalibratingOdometry::AdoptBackground(ScanResult* result) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<internal::BackgroundReplay> background = std::move(background_);
  internal::ReplayedPipeline replayed;
  try {
    replayed = background->Finish();
  } catch (const std::exception& e) {
    // The live pipeline carries on, as when the warm-up was never estimated.
    AddNote(result, std::string("calibration warm-up replay failed, not adopted: ") + e.what());
    results_.back().message = result->message;
    if (config_.kept_results > 0) {
      while (results_.size() > config_.kept_results) results_.pop_front();
    }
    return;
  }
  Adopt(std::move(replayed), MsSince(start), replay_note_, result);
}

void CalibratingOdometry::Adopt(internal::ReplayedPipeline replayed, double wait_ms,
                                const std::string& note, ScanResult* result) {
  // This scan's cost is the live scan's and the replay's (its CPU on whichever thread ran it, the
  // live thread's wait for it).
  ScanResult adopted = replayed.results.back();
  adopted.revised_scans = static_cast<int>(replayed.results.size()) - 1;
  adopted.milliseconds = result->milliseconds + wait_ms;
  adopted.cpu_ms = result->cpu_ms + replayed.cpu_ms;
  AddNote(&adopted, note);
  replayed.results.back() = adopted;
  last_replay_ = ReplayCost{replayed.cpu_ms, wait_ms, static_cast<int>(background_scans_)};
  // The swap: the replayed pipeline, its config (the caller's result bound), its results.
  const size_t kept = config_.kept_results;
  config_ = replayed.config;
  config_.kept_results = kept;
  warmup_results_ = std::move(results_);
  results_ = std::move(replayed.results);
  frozen_ = replayed.frozen;
  pipeline_ = std::move(replayed.pipeline);
  *result = adopted;
}

}  // namespace ctlio::lio
