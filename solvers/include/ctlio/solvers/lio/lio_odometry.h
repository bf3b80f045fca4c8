// The odometry interface shared by Singer-LIO and the IMU-as-input baseline (SPEC §4–§6), and
// what both pipelines have in common: the IMU buffer (ordering checks, gap detection, zero-order
// hold between samples), gravity initialisation, and the conversion of a scan into robot-frame
// points with times relative to the first scan.
//
// Use: feed the IMU samples in time order with AddImu, and each scan with AddScan once the IMU
// covers its end. Every scan returns a ScanResult whose status says whether the estimate is
// trustworthy (kOk), or why not — the odometry never returns a silent garbage pose: degenerate
// scans, IMU gaps and initialisation failures are flagged with a message.
#pragma once

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// One piece of the zero-order-hold IMU signal: sample held constant for dt seconds.
struct ImuSegment {
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
  double t_begin = 0.0;  // seconds (odometry time)
  double dt = 0.0;
};

class LioOdometry {
 public:
  explicit LioOdometry(const OdometryConfig& config);
  virtual ~LioOdometry() = default;
  LioOdometry(const LioOdometry&) = delete;
  LioOdometry& operator=(const LioOdometry&) = delete;

  // Throws std::invalid_argument if the sample is not finite or older than the previous one
  // (a duplicate timestamp is dropped and counted in duplicate_imu_samples()).
  void AddImu(const ImuSample& sample);
  // Processes one scan. Throws std::invalid_argument for a scan out of order or with mismatched
  // point/time arrays; everything else (too few points, IMU gaps, failed initialisation,
  // divergence) is reported in the result's status.
  ScanResult AddScan(const LidarScan& scan);

  const OdometryConfig& config() const { return config_; }
  const std::vector<ScanResult>& results() const { return results_; }
  size_t duplicate_imu_samples() const { return duplicate_imu_; }
  bool initialised() const { return initialised_; }
  // Gravity-aligned frame i → map frame m (valid once initialised()).
  const Mat3& C_mi() const { return C_mi_; }
  // The window the pipeline solves (SPEC §5): its states, residual blocks and marginal prior.
  const SlidingWindow& window() const { return window_; }
  SlidingWindow& window() { return window_; }
  // What the most recent Schur-complement marginalisation did (empty before the first one).
  const MarginalizationReport& last_marginalization() const { return last_marginalization_; }
  int num_marginalizations() const { return num_marginalizations_; }

 protected:
  // A scan prepared for the estimators: robot-frame points, times in seconds relative to the
  // origin (the first scan's start).
  struct PreparedScan {
    double t_begin = 0.0, t_end = 0.0;
    int64_t end_ns = 0;
    std::vector<TimedPoint> points;     // range-gated and subsampled, robot frame
    std::vector<TimedPoint> keypoints;  // subset used in the residuals
  };

  // The first scan (after gravity initialisation): build the first state(s) and the map.
  virtual void Initialise(const PreparedScan& scan, ScanResult* result) = 0;
  // Every later scan.
  virtual void Process(const PreparedScan& scan, ScanResult* result) = 0;

  double Seconds(int64_t t_ns) const { return 1e-9 * static_cast<double>(t_ns - origin_ns_); }
  // The zero-order-hold IMU signal over [t_a, t_b] (seconds); the sample in force at t_a is the
  // last one at or before t_a (or the first one if none). Returns the longest hole between
  // consecutive samples inside [t_a, t_b] (including the ends) in *max_gap.
  std::vector<ImuSegment> ImuSegments(double t_a, double t_b, double* max_gap) const;
  // All buffered samples with t_a < t ≤ t_b.
  std::vector<ImuSample> ImuSamples(double t_a, double t_b) const;
  // Drops samples that can no longer be needed (older than t minus one sample).
  void TrimImu(double t);

  // The association/solve rounds both pipelines share (SPEC §4): each round removes the previous
  // round's lidar residuals, lets `add_lidar` add this round's (through window_, from the current
  // estimate), drops them all if fewer than config.min_associations (degenerate scan: the prior
  // and IMU carry the state), and solves the window; stops when `newest_pose` moves less than the
  // convergence thresholds. `new_loss` gives the robust loss of one round (the window owns it).
  // Fills rounds, iterations, cost, associations and the associate/solve times; returns whether
  // the scan was degenerate. The lidar residuals of the last round stay in the window.
  using AddLidarResiduals =
      std::function<void(ceres::LossFunction* loss, std::vector<ceres::ResidualBlockId>* blocks)>;
  bool SolveRounds(const AddLidarResiduals& add_lidar, const std::function<SE3()>& newest_pose,
                   ScanResult* result);
  // Schur-complement marginalisation of the given states into one prior on the states they are
  // connected to (SlidingWindow::Marginalize, SPEC §5); times it into result->ms_marginalize.
  void MarginalizeStates(const std::vector<StateId>& ids, ScanResult* result);
  // Wall milliseconds since t0 (the per-stage times of ScanResult).
  static double MsSince(std::chrono::steady_clock::time_point t0);
  // Sets the status/message of a degenerate scan unless something worse was reported.
  void ReportDegenerate(ScanResult* result) const;
  // A new lidar loss (cauchy/huber per config, nullptr for none); the window takes ownership
  // once a residual uses it (ref-counted by Ceres), so the caller deletes it only if unused.
  ceres::LossFunction* NewLidarLoss() const;

  LidarFrontend frontend_;
  OdometryConfig config_;
  SlidingWindow window_;
  Mat3 C_mi_ = Mat3::Identity();
  Vec3 gravity_map() const { return C_mi_ * Vec3(0, 0, -config_.gravity); }
  bool uses_imu() const { return config_.method != LioMethod::kLidarOnly; }

 private:
  bool InitialiseGravity(double t_end, std::string* message);

  std::deque<ImuSample> imu_;
  size_t duplicate_imu_ = 0;
  int64_t origin_ns_ = 0;
  int64_t last_scan_end_ns_ = 0;
  bool have_origin_ = false;
  bool initialised_ = false;
  std::vector<ScanResult> results_;
  MarginalizationReport last_marginalization_;
  int num_marginalizations_ = 0;
};

// The pipeline of config.method.
std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config);

}  // namespace ctlio::lio
