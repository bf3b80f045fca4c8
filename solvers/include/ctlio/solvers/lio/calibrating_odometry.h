// The odometry a program runs: the single-pass pipeline (LioOdometry, lio_odometry.h) with the
// online calibration's warm-up replay around it (calibration_options.h, warmup_replay_s). Without
// a replay configured it only forwards to the one pipeline and keeps the result history.
//
// With one, the first warmup_replay_s seconds of input (every IMU sample and scan as given) are
// kept while the live pipeline processes them. After the first scan that ends past the span and
// was estimated, the span is processed again by a fresh pipeline started from the calibration the
// live one ended with (ReplayConfig), in warmup_replay_passes passes, the last one optionally
// held over the span (HoldCalibrationUntil) or frozen (FrozenCalibration); that pipeline replaces
// the live one, which is dropped, and carries on. If twice the span passes without an estimated
// scan, the kept data are dropped with a note and the live pipeline carries on.
//
//   AddScan ─▶ pipeline ─▶ [keep the span] ─▶ span reached, estimated? ─▶ replay passes ─▶ swap
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio {

class CalibratingOdometry {
 public:
  // Throws std::invalid_argument naming the field for an invalid config (OdometryConfig::Validate).
  explicit CalibratingOdometry(const OdometryConfig& config);
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
  // The passes over the kept data, the swap, and `result` replaced by the replay's.
  void Replay(double span_s, ScanResult* result);
  void Record(const ScanResult& result, bool bounded);

  OdometryConfig config_;
  double trajectory_rate_hz_ = 0.0;
  std::unique_ptr<LioOdometry> pipeline_;
  std::deque<ScanResult> results_;
  std::deque<ScanResult> warmup_results_;
  // The warm-up span as given: every IMU sample, and every scan with the number of samples
  // added before it.
  bool keeping_ = false;
  std::vector<ImuSample> warmup_imu_;
  std::vector<std::pair<LidarScan, size_t>> warmup_scans_;
  // After a frozen last pass (calibration.warmup_replay_freeze): what every result reports.
  std::optional<ScanResult::CalibrationEstimate> frozen_;
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
