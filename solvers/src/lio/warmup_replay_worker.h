// The calibration warm-up replay's work (calibrating_odometry.h), the same on either thread: the
// passes over the kept warm-up span, then, in the background, the scans that arrived since (the
// catch-up), so that the replayed pipeline is where the live one is when it is adopted.
//
//   live thread:   scan k (span reached) ─▶ scans k+1 … S−1 (live pipeline, each also Push-ed)
//                                            ─▶ scan S: Push, Finish (wait), swap
//   second thread:  passes over scans 0…k ─▶ catch-up k+1 … S ─▶ done
//
// The replayed pipeline sees the same inputs in the same order as it would inside the live
// thread, so what is adopted does not depend on thread timing; only the wait does.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio::internal {

// The warm-up span as given: every IMU sample, and every scan with the number of samples added
// before it.
struct WarmupSpan {
  std::vector<ImuSample> imu;
  std::vector<std::pair<LidarScan, size_t>> scans;
};

// A pipeline inside CalibratingOdometry (the live one or a replay's): the history is the driver's,
// so it keeps one result; the dense trajectory at trajectory_rate_hz.
std::unique_ptr<LioOdometry> MakeReplayPipeline(OdometryConfig config, double trajectory_rate_hz);

// What the passes hand on: the pipeline that carries on, its config, the report a frozen last
// pass gives every result, the results of every scan it processed (the last pass's over the span,
// then the catch-up's), and the CPU of the thread that ran it.
struct ReplayedPipeline {
  std::unique_ptr<LioOdometry> pipeline;
  OdometryConfig config;
  std::optional<ScanResult::CalibrationEstimate> frozen;
  std::deque<ScanResult> results;
  int passes_run = 0;
  double cpu_ms = 0.0;

  // The catch-up: one more input, as the live pipeline had it.
  void AddImu(const ImuSample& sample) { pipeline->AddImu(sample); }
  void AddScan(const LidarScan& scan);
};

// The calibration.warmup_replay_passes passes of `config` over `span` (span_s seconds from the
// first scan's begin to the last's end), the first from `start_values` (the live estimate after
// the span's last scan), each later one from the previous one's. A pipeline made like
// CalibratingOdometry's (kept_results 1, the dense trajectory at trajectory_rate_hz). Stops
// between scans once *cancel is set (the result is then not to be used).
ReplayedPipeline ReplayWarmup(const OdometryConfig& config, double trajectory_rate_hz,
                              const WarmupSpan& span, double span_s,
                              const ScanResult::CalibrationEstimate& start_values,
                              const std::atomic<bool>* cancel = nullptr);

// ReplayWarmup on a second thread, then every input Push-ed since, in order.
class BackgroundReplay {
 public:
  BackgroundReplay(OdometryConfig config, double trajectory_rate_hz, WarmupSpan span, double span_s,
                   ScanResult::CalibrationEstimate start_values);
  // Cancels the work (between two scans) and joins.
  ~BackgroundReplay();
  BackgroundReplay(const BackgroundReplay&) = delete;
  BackgroundReplay& operator=(const BackgroundReplay&) = delete;

  void Push(const ImuSample& sample);
  void Push(const LidarScan& scan);
  // Waits until everything pushed has been processed and the thread has ended; the replayed
  // pipeline, or rethrows what the replay threw. Once only.
  ReplayedPipeline Finish();

 private:
  void Run();

  const OdometryConfig config_;
  const double trajectory_rate_hz_;
  const WarmupSpan span_;
  const double span_s_;
  const ScanResult::CalibrationEstimate start_values_;
  std::mutex mutex_;
  std::condition_variable pushed_;
  std::deque<std::variant<ImuSample, LidarScan>> queue_;
  bool closed_ = false;
  std::atomic<bool> cancel_{false};
  ReplayedPipeline out_;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once every other member exists
};

}  // namespace ctlio::lio::internal
