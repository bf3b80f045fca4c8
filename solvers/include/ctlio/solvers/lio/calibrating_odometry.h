// The odometry a program runs: the single-pass pipeline (LioOdometry, lio_odometry.h) with the
// online calibration's warm-up replay around it (calibration_options.h, warmup_replay_s). Without
// a replay configured it only forwards to the one pipeline and keeps the result history.
//
// With calibration.warmup_forget_s instead, nothing is kept: after the first estimated scan that
// ends past that span, the pipeline's marginal priors forget the calibration
// (LioOdometry::ForgetCalibrationInformation) and it carries on.
//
// With a replay, the first warmup_replay_s seconds of input (every IMU sample and scan as given)
// are kept while the live pipeline processes them. After the first scan that ends past the span and
// was estimated, the span is processed again by a fresh pipeline started from the calibration the
// live one ended with (ReplayConfig), in warmup_replay_passes passes, the last one optionally
// held over the span (HoldCalibrationUntil) or frozen (FrozenCalibration); that pipeline replaces
// the live one, which is dropped, and carries on. If twice the span passes without an estimated
// scan, the kept data are dropped with a note and the live pipeline carries on.
//
//   AddScan ─▶ pipeline ─▶ [keep the span] ─▶ span reached, estimated? ─▶ replay passes ─▶ swap
//
// Where the passes run is ReplaySchedule's: inside the scan that reached the span (the live
// output pauses for all of them), or on a second thread while the live pipeline carries on, the
// replayed one catching up on the scans that arrive meanwhile and swapped in at a scan fixed by
// the data (warmup_replay_worker.h), so that what is adopted does not depend on thread timing.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio {

namespace internal {
class BackgroundReplay;
struct ReplayedPipeline;
}  // namespace internal

// When the warm-up replay runs and when its pipeline replaces the live one.
struct ReplaySchedule {
  // false: the passes run inside the AddScan of the scan that reached the span, whose result is
  // then the replay's (the live output pauses for the whole replay). true: on a second thread,
  // while the live pipeline processes the scans that follow; the replayed pipeline processes them
  // too, after its passes, and is adopted with the first scan that ends adopt_after_s or more
  // after the one that reached the span (seconds of data: the same scan on every run). There the
  // live thread waits for it if it is late (last_replay().wait_ms); Finish adopts it at the end of
  // the input if that comes first. From the adopting scan on, the results are those of the
  // replay inside the scan that reached the span, bit for bit; before it, the live pipeline's.
  bool background = false;
  double adopt_after_s = 60.0;
};

class CalibratingOdometry {
 public:
  // Throws std::invalid_argument naming the field for an invalid config (OdometryConfig::Validate).
  explicit CalibratingOdometry(const OdometryConfig& config, ReplaySchedule schedule = {});
  ~CalibratingOdometry();
  CalibratingOdometry(const CalibratingOdometry&) = delete;
  CalibratingOdometry& operator=(const CalibratingOdometry&) = delete;

  // LioOdometry::AddImu / AddScan (the same checks and exceptions); the scan that replays the
  // warm-up returns the replay's result for it, with ScanResult::revised_scans > 0.
  bool AddImu(const ImuSample& sample);
  ScanResult AddScan(const LidarScan& scan);

  // The config of the pipeline that carries on, as given: after a replay its calibration starts
  // from the warm-up's estimates and its calibration.warmup_replay_s is 0.
  const OdometryConfig& config() const { return config_; }
  // The newest config().kept_results results (all with 0), oldest first. While a warm-up replay is
  // pending, every result of its span stays, and after it the replayed span's results are all
  // here (the replay revised them); the bound holds again from the next scan.
  const std::deque<ScanResult>& results() const { return results_; }
  // The results returned live for the scans of the warm-up span, before the replay replaced
  // them in results() (empty until a replay).
  const std::deque<ScanResult>& warmup_results() const { return warmup_results_; }
  // True while the warm-up's data are kept for a replay.
  bool keeps_warmup() const { return keeping_; }
  // True while a background replay runs or waits to be adopted.
  bool replay_pending() const { return background_ != nullptr; }
  // The end of the input: a pending background replay is adopted (waiting for it to catch up on
  // every scan given) and the newest scan's result as replayed returned, as AddScan returns the
  // adopting scan's (revised_scans > 0); nothing otherwise.
  std::optional<ScanResult> Finish();

  // The replay's cost, once adopted: its CPU (the passes and the catch-up, on whichever thread),
  // the live thread's wait for it (the whole replay when not in the background) and the scans it
  // processed (passes × span + catch-up).
  struct ReplayCost {
    double cpu_ms = 0.0, wait_ms = 0.0;
    int scans = 0;
  };
  const std::optional<ReplayCost>& last_replay() const { return last_replay_; }

  // The pipeline that processes the next scan (after a replay, the replayed one). It keeps only
  // its newest result; the history is results().
  const LioOdometry& pipeline() const { return *pipeline_; }
  LioOdometry& pipeline() { return *pipeline_; }

  // The pipeline's (lio_odometry.h).
  size_t duplicate_imu_samples() const { return pipeline_->duplicate_imu_samples(); }
  size_t rejected_imu_samples() const { return pipeline_->rejected_imu_samples(); }
  bool initialised() const { return pipeline_->initialised(); }
  const Mat3& C_mi() const { return pipeline_->C_mi(); }
  const SlidingWindow& window() const { return pipeline_->window(); }
  SlidingWindow& window() { return pipeline_->window(); }
  const MarginalizationReport& last_marginalization() const {
    return pipeline_->last_marginalization();
  }
  int num_marginalizations() const { return pipeline_->num_marginalizations(); }
  std::vector<std::pair<int64_t, SE3>> SampleNewestInterval(double rate_hz) const {
    return pipeline_->SampleNewestInterval(rate_hz);
  }
  const std::vector<Vec3>* newest_map_points() const { return pipeline_->newest_map_points(); }
  // The replayed pipeline carries the dense trajectory on from its own first scan (the replay
  // revised the span's estimates); what the live one had not handed out is dropped.
  void SampleFinalTrajectory(double rate_hz);
  FinalTrajectory::Samples TakeFinalTrajectory() { return pipeline_->TakeFinalTrajectory(); }
  FinalTrajectory::Samples FinalTrajectoryTail() const { return pipeline_->FinalTrajectoryTail(); }

 private:
  // After `result`'s scan: once the kept data span warmup_replay_s and the scan was estimated,
  // replays them (Replay); gives up (note, data dropped) if twice the span passes without an
  // estimate.
  void MaybeReplay(ScanResult* result);
  // calibration.warmup_forget_s: after the first estimated scan ending that long after the first
  // scan began, the pipeline's marginal priors forget the calibration (noted in `result`).
  void MaybeForget(const LidarScan& scan, ScanResult* result);
  // The passes over the kept data, here or (ReplaySchedule::background) started on a second
  // thread.
  void Replay(double span_s, ScanResult* result);
  // The background replay's wait and swap, with `result` (the live one of the adopting scan).
  void AdoptBackground(ScanResult* result);
  // The swap: the replayed pipeline carries on; `result` becomes its result for the same scan.
  void Adopt(internal::ReplayedPipeline replayed, double wait_ms, const std::string& note,
             ScanResult* result);
  void Record(const ScanResult& result, bool bounded);

  OdometryConfig config_;
  ReplaySchedule schedule_;
  double trajectory_rate_hz_ = 0.0;
  std::unique_ptr<LioOdometry> pipeline_;
  std::deque<ScanResult> results_;
  std::deque<ScanResult> warmup_results_;
  // The warm-up span as given: every IMU sample, and every scan with the number of samples
  // added before it.
  bool keeping_ = false;
  std::vector<ImuSample> warmup_imu_;
  std::vector<std::pair<LidarScan, size_t>> warmup_scans_;
  // calibration.warmup_forget_s: pending until done; the first scan's begin.
  bool forgetting_ = false;
  int64_t first_begin_ns_ = -1;
  // After a frozen last pass (calibration.warmup_replay_freeze): what every result reports.
  std::optional<ScanResult::CalibrationEstimate> frozen_;
  // A background replay and the end time of the scan that adopts it.
  std::unique_ptr<internal::BackgroundReplay> background_;
  int64_t adopt_ns_ = 0;
  size_t background_scans_ = 0;  // the kept span's and the catch-up's scans
  std::string replay_note_;
  std::optional<ReplayCost> last_replay_;
};

// The config of a replay pass started from `estimate` (the calibration after the live warm-up or
// after the previous pass): `config` without a replay of its own, the estimates as start values
// and prior means (σ unchanged), and along each coordinate `estimate.unobservable` marks, the
// configured value instead.
OdometryConfig ReplayConfig(const OdometryConfig& config,
                            const ScanResult::CalibrationEstimate& estimate);

// What a frozen pass with `config` (ReplayConfig(…, estimate)) reports with every result: the
// values it runs with, the estimate's σ and observability, every coordinate held.
ScanResult::CalibrationEstimate FrozenCalibration(const ScanResult::CalibrationEstimate& estimate,
                                                  const OdometryConfig& config);

}  // namespace ctlio::lio
