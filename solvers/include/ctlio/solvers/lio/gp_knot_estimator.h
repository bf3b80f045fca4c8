// The states and factors of Singer-LIO (the paper's method, SPEC §2–§4): one GP knot
// {T_rm, ϖ, ϖ̇, b} per scan end (and with window.knots_per_scan = K > 1, K − 1 more at equal
// spacing inside the sweep, so fast motion is not interpolated over a whole sweep), the SE(3)
// Singer prior between knots, the gyro and the
// accelerometer as measurements of the interpolated state at every IMU time (biases interpolated
// linearly between knots, gravity C_mi from the initialisation), a bias random walk between
// knots, and the keypoints as ContinuousPointToPlane residuals (ContinuousLidarTerm). The
// `lidar_gyro` method drops the accelerometer; `lidar_only` drops the IMU and the biases.
// Several IMUs (OdometryConfig::imus): every sample of every IMU is a measurement of the state at
// its own time with its IMU's mounting (lever arm and rotation, imu_mounting.h) and noise, and
// each IMU has its own bias blocks (KnotKeys::Bias) with their own random walk.
// Clock offsets (OdometryConfig::calibration, Singer-LIO and lidar_gyro): IMU j's sample stamped
// t measures the state at t + δ_j. Estimated: one 1-D block per IMU (TimeOffsetKey) with a
// Gaussian prior, read by the time-offset IMU factors (imu_gyro_time_offset.h); a sample goes to
// the interval that holds t + δ̄_j for the estimate δ̄_j when its knot is added (each sample once:
// the stamps taken follow on from the previous interval's). Configured but not estimated: the
// fixed-time factors at t + δ_j. Neither: the estimator without offsets, bit for bit.
// Online calibration (OdometryConfig::calibration.estimate_extrinsic): the extrinsic T_rl is a
// static state (kExtrinsicKey) with a prior on the configured value, read by every lidar
// residual (ContinuousPointToPlaneExtrinsic); the map points are placed with its estimate.
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/imu/imu_mounting.h"
#include "ctlio/solvers/lio/accel_loss_schedule.h"
#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

class GpKnotEstimator final : public Estimator {
 public:
  GpKnotEstimator(const OdometryConfig& config, const ImuBuffer& imu);

  void Initialise(const PreparedScan& scan, const Mat3& C_mi, SlidingWindow* window) override;
  void AddState(const PreparedScan& scan, SlidingWindow* window, ScanResult* result) override;
  std::unique_ptr<LidarTerm> MakeLidarTerm(const PreparedScan& scan,
                                           SlidingWindow* window) const override;
  void MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const override;
  void Report(ScanResult* result) const override;

  int num_states() const override { return static_cast<int>(knots_.size()); }
  std::vector<StateId> OldestKeys() const override;
  std::vector<StateId> NewestKeys() const override;
  void DropOldest() override { knots_.pop_front(); }
  double newest_time() const override { return knots_.back().t; }
  SE3 NewestPose() const override;
  SE3 PreviousPose() const override;  // at the previous scan's end
  StateId NewestPoseKey() const override { return knots_.back().keys.pose; }
  // T_rm: Exp(δ)·T_rm is the body motion T_mr·Exp(−δ).
  Mat6 NewestPoseTangentFromBody() const override { return -Mat6::Identity(); }
  double previous_time() const override { return ScanStart().t; }
  std::vector<SE3> PosesSincePrevious(const std::vector<double>& t) const override;
  std::vector<double> StateTimes() const override;
  std::vector<SE3> SealOldest(const std::vector<double>& t) override;
  std::vector<SE3> UnsealedPoses(const std::vector<double>& t) const override;
  std::string ImuGapRecovery() const override { return "the GP prior bridges it"; }
  const ImuTermBlocks& NewestImuBlocks() const override { return imu_blocks_; }

 private:
  // A knot's blocks live in the window (which owns the storage).
  struct Knot {
    double t = 0.0;
    KnotKeys keys;
    double* pose = nullptr;
    double* velocity = nullptr;
    double* acceleration = nullptr;
    std::vector<double*> bias;  // per IMU; empty for lidar_only
  };
  bool uses_imu() const { return config_.method != LioMethod::kLidarOnly; }
  bool estimates_extrinsic() const { return config_.calibration.estimate_extrinsic; }
  int num_imus() const { return uses_imu() ? config_.num_imus() : 0; }
  // `bias`: the initial value of every IMU's bias, per IMU.
  Knot AddKnot(double t, const SE3& T_rm, const Vec6& w, const Vec6& dw,
               const std::vector<Vec6>& bias, SlidingWindow* window);
  // A knot's time and its GP state {T_rm, ϖ, ϖ̇}: what the interpolation between knots reads.
  struct TimedState {
    double t = 0.0;
    gp::KnotState x;
  };
  static TimedState ValueOf(const Knot& k);
  // T_mr(τ) between knots a and b from the current estimates (GP interpolation, SPEC §2), and
  // between two knot states.
  SE3 PoseAt(const Knot& a, const Knot& b, double tau) const;
  SE3 PoseBetween(const TimedState& a, const TimedState& b, double tau) const;
  // T_mr at each of `t` (ascending) over consecutive knot states (time order): at a knot's time
  // its pose, between two knots the interpolation.
  std::vector<SE3> PosesOver(const std::vector<TimedState>& chain,
                             const std::vector<double>& t) const;
  // The knot at the previous scan's end (the newest before the last AddState), its index in
  // knots_, and T_mr(τ) for τ in [ScanStart().t, newest_time()] on the interval between the
  // knots around τ.
  size_t ScanStartIndex() const;
  const Knot& ScanStart() const { return knots_[ScanStartIndex()]; }
  SE3 PoseSinceScanStart(double tau) const;
  // The sweep's knot count: window.knots_per_scan, or more when window.adaptive_knots_* find
  // the motion of its IMU samples too curved for fewer (knot_spacing.h).
  int KnotsForScan(double t_prev, double t_end) const;
  // One knot at t after the newest, with the motion prior, bias walk and IMU measurements of the
  // interval between them.
  void AddKnotAndFactors(double t, SlidingWindow* window, ScanResult* result);
  // The new knot's starting value at t from the previous knot and the interval's samples per
  // IMU: window.imu_prediction's integration of the IMU (imu_knot_prediction.h), or constant
  // body velocity with the newest gyro sample's rate.
  // The mean twist of the estimate over the gap_prediction_span seconds before knot `prev`
  // (Log(T_prev·T_ref⁻¹)/(t_prev − t_ref), T_ref the newest state at least that old, or the
  // oldest kept), or nothing before a tenth of the span is covered.
  std::optional<Vec6> MeanTwist(const Knot& prev) const;
  gp::KnotState InitialGuess(const Knot& prev, double t,
                             const std::vector<std::vector<ImuSample>>& imu,
                             const SlidingWindow& window) const;
  // Gyro and accelerometer samples of IMU `imu` in (prev.t, k.t] as measurements (SPEC §3).
  void AddImuMeasurements(const Knot& prev, const Knot& k, int imu,
                          const std::vector<ImuSample>& samples, SlidingWindow* window,
                          ScanResult* result);
  // Before a scan's knots: the accelerometer-bias covariance for the loss schedule (accel_loss_),
  // while it watches, and what it decided into `result`.
  void UpdateAccelLoss(const SlidingWindow& window, ScanResult* result);
  // Clock offsets in use (estimated or configured non-zero), and IMU j's current δ_j.
  bool time_offsets() const { return uses_imu() && time_offsets_; }
  double TimeOffset(int imu, const SlidingWindow& window) const;

  OdometryConfig config_;
  const ImuBuffer& imu_;
  gp::SingerModel<6> model_;
  std::vector<imu::ImuMounting> mountings_;  // per IMU
  std::deque<Knot> knots_;                   // oldest first
  double* extrinsic_ = nullptr;              // T_rl (kExtrinsicKey) when estimated
  int64_t next_knot_ = 0;
  int scan_knots_ = 0;        // knots the last AddState added (0 after Initialise)
  bool split_sweep_ = false;  // the last AddState's sweep got more knots than knots_per_scan
  // The sweep's keypoints under its own budget (window.adaptive_knots_max_keypoints on a split
  // sweep, window.slow_sweep_max_keypoints on a slow one; sweep_keypoint_budget.h). The lidar
  // term holds a reference to them until the next AddState; used when use_own_keypoints_.
  std::vector<TimedPoint> own_keypoints_;
  bool use_own_keypoints_ = false;
  bool time_offsets_ = false;
  std::vector<double> last_stamp_;         // per IMU: the newest stamp [s] already a measurement
  const SlidingWindow* window_ = nullptr;  // for Report (the offsets' blocks)
  std::optional<TimedState> sealed_;       // the final value of the knot sealed last
  // The oldest knot at each AddState (solved at least once) over the last
  // window.gap_prediction_span seconds, oldest first: where the mean twist a knot in an IMU
  // outage starts from reaches back to.
  std::deque<TimedState> history_;
  ImuTermBlocks imu_blocks_;  // those the last AddState added
  // The accelerometer's Cauchy scale per IMU, relaxed once its bias is known
  // (imu.accel_loss_relax_bias_sigma); read from the window before each AddState.
  AccelLossSchedule accel_loss_;
};

}  // namespace ctlio::lio
