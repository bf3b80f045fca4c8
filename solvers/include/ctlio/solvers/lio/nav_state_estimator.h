// The states and factors of the IMU-as-input baseline (SPEC §3, §4, §6): navigation states
// {T_wb, v, b} at scan ends, one preintegrated IMU factor (Forster et al. 2017) between
// consecutive states, and the keypoints deskewed by integrating the IMU from the previous state
// (re-done every association round) as PointToPlaneWorld residuals at the single pose of the
// scan end. Same front end, registration and window as Singer-LIO: only the motion model differs.
//
// IMU gaps: an interval between two states with a hole in the IMU longer than init.max_imu_gap
// is not preintegrated (holding the last sample over the hole integrates a stale acceleration
// into a diverging prediction). The new state is predicted by the constant twist of the last two
// states, its keypoints are deskewed by the constant twist between the states, and the two
// states are linked only by a weak velocity random walk (imu.gap_velocity_walk) and the bias
// random walk: the lidar alone registers the scan. The first interval with the IMU back is
// preintegrated from the estimated state again (the preintegration is re-anchored).
//
// Online calibration (calibration_options.h), with the same states as Singer-LIO's
// (calibration_blocks.h), so CalibrationStates holds, assesses and reports them alike: the
// extrinsic T_rl, through which every keypoint enters from the lidar frame, and the IMU's clock
// offset δ (one IMU). A state sits at its scan end t on the lidar clock, IMU time t − δ: the
// deskew integrates the samples stamped in [t_prev − δ, t − δ] at the current estimate (every
// round), and the preintegrated factor, taken at the estimate δ̄ when the state was added, moves
// its interval with δ to first order (preintegrated_imu_time_offset_factor.h): δ is informed where
// the IMU's motion over the shifted interval has to meet the lidar's poses at the scan ends, and
// through the deskew, which each keypoint's residual moves with δ to first order as well
// (point_to_plane_world_calibrated.h): held fixed instead, the deskew at a wrong δ biases the
// poses until the IMU factor agrees with it (fast/100 from δ = 0: −8 ms with the deskew held at
// 0; the true 20 ms within 0.5 s with the deskew held at the truth).
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/estimator.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

class NavStateEstimator final : public Estimator {
 public:
  NavStateEstimator(const OdometryConfig& config, const ImuBuffer& imu);

  void Initialise(const PreparedScan& scan, const Mat3& C_mi, SlidingWindow* window) override;
  void AddState(const PreparedScan& scan, SlidingWindow* window, ScanResult* result) override;
  std::unique_ptr<LidarTerm> MakeLidarTerm(const PreparedScan& scan,
                                           SlidingWindow* window) const override;
  void MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const override;
  void Report(ScanResult* result) const override;

  int num_states() const override { return static_cast<int>(states_.size()); }
  std::vector<StateId> OldestKeys() const override { return states_.front().keys.All(); }
  std::vector<StateId> NewestKeys() const override { return states_.back().keys.All(); }
  void DropOldest() override { states_.pop_front(); }
  double newest_time() const override { return states_.back().t; }
  SE3 NewestPose() const override;
  SE3 PreviousPose() const override;
  StateId NewestPoseKey() const override { return states_.back().keys.pose; }
  // T_wb: Exp(δ)·T_wb = T_wb·Exp(Ad(T_wb⁻¹)δ), so δ = Ad(T_wb)·δ_body.
  Mat6 NewestPoseTangentFromBody() const override { return NewestPose().Adjoint(); }
  double previous_time() const override { return states_[states_.size() - 2].t; }
  std::vector<SE3> PosesSincePrevious(const std::vector<double>& t) const override;
  std::vector<double> StateTimes() const override;
  std::vector<SE3> SealOldest(const std::vector<double>& t) override;
  std::vector<SE3> UnsealedPoses(const std::vector<double>& t) const override;
  std::string ImuGapRecovery() const override;
  const ImuTermBlocks& NewestImuBlocks() const override { return imu_blocks_; }

  // A state's blocks live in the window.
  struct State {
    double t = 0.0;
    NavStateKeys keys;
    double* pose = nullptr;      // T_wb = T_mr (body → world = map)
    double* velocity = nullptr;  // world frame, 3
    double* bias = nullptr;      // [b_a; b_g]
    bool after_gap = false;      // the interval from the previous state is not preintegrated
  };
  // Poses T_wb at the boundaries of the IMU segments over [from.t, t_end], integrated from the
  // current estimate of `from` (pose, velocity, bias); between them a constant twist.
  struct DeskewTable {
    std::vector<double> t;
    std::vector<SE3> T_wb;
    SE3 T_end_inv;  // T_wb.back()⁻¹
    SE3 Interpolate(double tau) const;
    // The body twist ν = [v; ω] (T(s + h) = T(s)·Exp(h·ν)) over the step holding τ.
    Vec6 TwistAt(double tau) const;
    // q (robot frame at τ) moved into the body frame at the table's end.
    Vec3 ToEnd(double tau, const Vec3& q) const { return T_end_inv * (Interpolate(tau) * q); }
  };
  // The table's times are on the lidar clock: IMU time + δ (the current estimate).
  DeskewTable Integrate(const State& from, double t_end) const;
  // Online calibration: the estimate (else the configured value) of T_rl and δ, and which are
  // states.
  bool estimates_extrinsic() const { return config_.calibration.estimate_extrinsic; }
  bool estimates_time_offset() const { return config_.calibration.estimate_time_offset; }
  SE3 Extrinsic() const;
  double TimeOffset() const;
  const OdometryConfig& config() const { return config_; }
  // The deskew table of the interval ending at `to` (IMU-integrated, or the constant twist
  // between the two states across a gap).
  DeskewTable Deskew(const State& from, const State& to) const;

 private:
  // The signal of the input IMU (config.input_imu) over [t_a, t_b] at the midpoints of the
  // zero-order-hold segments (imu_midpoint.h), rotated into the robot frame. Its lever arm is not
  // modelled: ω̇×p would need the derivative of the gyro.
  // t_a, t_b: IMU-clock times (segments on the IMU clock).
  std::vector<ImuSegment> InputSegments(double t_a, double t_b, double* max_gap) const;
  State AddNavState(double t, const SE3& T_wb, const Vec3& v, const Vec6& bias,
                    SlidingWindow* window);
  // Across an IMU gap: the constant-twist prediction and the velocity random walk.
  void AddStateAcrossGap(const State& prev, double t_end, SlidingWindow* window);
  // T_wb(τ) on the segment from a state to T_b at t_b, given `from_a`, the motion propagated from
  // the state (Deskew): the propagation with its end mismatch against T_b spread over the segment.
  static SE3 AnchoredPose(const DeskewTable& from_a, double t_b, const SE3& T_b, double tau);

  OdometryConfig config_;
  const ImuBuffer& imu_;
  Vec3 gravity_map_ = Vec3::Zero();
  const SlidingWindow* window_ = nullptr;  // set by Initialise (the calibration states)
  std::deque<State> states_;               // oldest first
  int64_t next_state_ = 0;
  // The motion propagated from the final value of the state sealed last to the next state's time.
  std::optional<DeskewTable> sealed_;
  ImuTermBlocks imu_blocks_;  // the preintegrated factor the last AddState added
};

}  // namespace ctlio::lio
