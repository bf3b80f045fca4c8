#include "warmup_replay_worker.h"

#include <stdexcept>
#include <string>

#include "ctlio/solvers/lio/calibrating_odometry.h"
#include "scan_clock.h"

namespace ctlio::lio::internal {

namespace {

bool Cancelled(const std::atomic<bool>* cancel) {
  return cancel != nullptr && cancel->load(std::memory_order_relaxed);
}

}  // namespace

std::unique_ptr<LioOdometry> MakeReplayPipeline(OdometryConfig config, double trajectory_rate_hz) {
  config.kept_results = 1;
  auto pipeline = std::make_unique<LioOdometry>(config);
  pipeline->SampleFinalTrajectory(trajectory_rate_hz);
  return pipeline;
}

void ReplayedPipeline::AddScan(const LidarScan& scan) {
  ScanResult result = pipeline->AddScan(scan);
  if (frozen) result.calibration = *frozen;
  results.push_back(std::move(result));
}

ReplayedPipeline ReplayWarmup(const OdometryConfig& config, double trajectory_rate_hz,
                              const WarmupSpan& span, double span_s,
                              const ScanResult::CalibrationEstimate& start_values,
                              const std::atomic<bool>* cancel) {
  const double cpu_start = ThreadCpuMs();
  const CalibrationOptions& options = config.calibration;
  const int passes = options.warmup_replay_passes;
  ReplayedPipeline out;
  ScanResult::CalibrationEstimate start = start_values;
  for (int pass = 0; pass < passes && !Cancelled(cancel); ++pass) {
    const bool last = pass == passes - 1;
    out.config = ReplayConfig(config, start);
    const bool hold = last && options.warmup_replay_hold;
    if (hold) out.config.calibration.hold_gravity = true;
    out.frozen.reset();
    if (last && options.warmup_replay_freeze) {
      // ReplayConfig has put the values into the configuration: known values from here on.
      out.config.calibration.estimate_time_offset = false;
      out.config.calibration.estimate_extrinsic = false;
      out.frozen = FrozenCalibration(start, out.config);
    }
    out.pipeline = MakeReplayPipeline(out.config, trajectory_rate_hz);
    if (hold) {
      // The replay's clock starts at the first kept scan's begin, so its scans end within span_s.
      std::vector<bool> observable = start.unobservable;
      observable.flip();  // empty (no check): all
      out.pipeline->HoldCalibrationUntil(span_s, std::move(observable));
    }
    out.results.clear();
    size_t next_imu = 0;
    for (const auto& [scan, imu_before] : span.scans) {
      if (Cancelled(cancel)) break;
      for (; next_imu < imu_before; ++next_imu) out.AddImu(span.imu[next_imu]);
      out.AddScan(scan);
    }
    for (; next_imu < span.imu.size(); ++next_imu) out.AddImu(span.imu[next_imu]);
    if (Cancelled(cancel) || out.results.empty()) break;
    ++out.passes_run;
    // A pass that ends without an estimate is the one that carries on: nothing to start from.
    const ScanResult& end = out.results.back();
    if (end.status == ScanStatus::kFailed || !out.pipeline->initialised()) break;
    start = end.calibration;
  }
  out.cpu_ms = ThreadCpuMs() - cpu_start;
  return out;
}

BackgroundReplay::BackgroundReplay(OdometryConfig config, double trajectory_rate_hz,
                                   WarmupSpan span, double span_s,
                                   ScanResult::CalibrationEstimate start_values)
    : config_(std::move(config)),
      trajectory_rate_hz_(trajectory_rate_hz),
      span_(std::move(span)),
      span_s_(span_s),
      start_values_(std::move(start_values)),
      thread_([this] { Run(); }) {}

BackgroundReplay::~BackgroundReplay() {
  cancel_ = true;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  pushed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void BackgroundReplay::Push(const ImuSample& sample) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    queue_.emplace_back(sample);
  }
  pushed_.notify_one();
}

void BackgroundReplay::Push(const LidarScan& scan) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    queue_.emplace_back(scan);
  }
  pushed_.notify_one();
}

ReplayedPipeline BackgroundReplay::Finish() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  pushed_.notify_all();
  if (!thread_.joinable()) throw std::logic_error("BackgroundReplay::Finish called twice");
  thread_.join();
  if (error_) std::rethrow_exception(error_);
  return std::move(out_);
}

void BackgroundReplay::Run() {
  try {
    out_ = ReplayWarmup(config_, trajectory_rate_hz_, span_, span_s_, start_values_, &cancel_);
    const double cpu_start = ThreadCpuMs();
    while (!cancel_) {
      std::variant<ImuSample, LidarScan> input;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        pushed_.wait(lock, [this] { return closed_ || !queue_.empty(); });
        if (queue_.empty()) break;  // closed and drained
        input = std::move(queue_.front());
        queue_.pop_front();
      }
      if (const auto* sample = std::get_if<ImuSample>(&input)) {
        out_.AddImu(*sample);
      } else {
        out_.AddScan(std::get<LidarScan>(input));
      }
    }
    out_.cpu_ms += ThreadCpuMs() - cpu_start;
  } catch (...) {
    error_ = std::current_exception();
  }
}

}  // namespace ctlio::lio::internal
