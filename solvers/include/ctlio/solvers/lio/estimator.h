// What differs between the LIO pipelines: the states and the motion/IMU factors (SPEC §2–§4,
// §6). An Estimator only adds states and factors to the odometry's window and reads its
// estimate; the odometry (lio_odometry.h) owns the window, the IMU buffer, the front end and the
// registration, and runs the per-scan steps.
//
//   GpKnotEstimator   Singer-LIO, lidar_gyro, lidar_only: GP knots, IMU as a measurement
//   NavStateEstimator the IMU-as-input baseline: navigation states, preintegrated IMU
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/imu_buffer.h"
#include "ctlio/solvers/lio/imu_consistency.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/scan_registration.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// A scan prepared for the estimators: robot-frame points, times in odometry seconds.
struct PreparedScan {
  double t_begin = 0.0, t_end = 0.0;
  int64_t end_ns = 0;
  std::vector<TimedPoint> points;     // range-gated and subsampled, robot frame, time order
  std::vector<TimedPoint> keypoints;  // subset used in the residuals, time order
  // The extrinsic T_imu_lidar that moved the points into the robot frame: the configured one, or
  // the current estimate with online calibration (T_robot_lidar⁻¹ recovers the lidar-frame point).
  SE3 T_robot_lidar;
};

class Estimator {
 public:
  virtual ~Estimator() = default;

  // The first scan: the first state at the map origin, at rest, held constant where that fixes
  // the gauge, and the initial bias prior. C_mi from the gravity initialisation.
  virtual void Initialise(const PreparedScan& scan, const Mat3& C_mi, SlidingWindow* window) = 0;
  // A new state at the scan end and the factors tying it to the previous one (motion prior,
  // IMU). Throws if the scan cannot be processed (e.g. no IMU for a pipeline that needs it).
  virtual void AddState(const PreparedScan& scan, SlidingWindow* window, ScanResult* result) = 0;
  // The scan's keypoints as a measurement of the newest states (for ScanRegistration).
  virtual std::unique_ptr<LidarTerm> MakeLidarTerm(const PreparedScan& scan,
                                                   SlidingWindow* window) const = 0;
  // Every preprocessed point in the map frame, each moved by the estimated motion at its time,
  // written into *out (its capacity is reused: a sweep's ~50 000 points are megabytes, which a
  // fresh vector per scan faults in page by page).
  virtual void MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const = 0;
  // Writes the newest state's estimate (pose, velocity, bias) into the result.
  virtual void Report(ScanResult* result) const = 0;

  // States in the window, oldest first: their number, the keys of the oldest (to marginalise)
  // and forgetting it once the window has marginalised it.
  virtual int num_states() const = 0;
  virtual std::vector<StateId> OldestKeys() const = 0;
  // The keys of the states the last AddState added (their residual blocks are the newest scan's
  // factors): the newest state, or the sweep's knots with window.knots_per_scan > 1.
  virtual std::vector<StateId> NewestKeys() const = 0;
  virtual void DropOldest() = 0;
  // Time (odometry seconds) and map pose T_mr of the newest state and of the state at the
  // previous scan's end.
  virtual double newest_time() const = 0;
  virtual SE3 NewestPose() const = 0;
  virtual SE3 PreviousPose() const = 0;
  // The newest pose's state and A with δ_state = A·δ_body for its tangent (degeneracy.h).
  virtual StateId NewestPoseKey() const = 0;
  virtual Mat6 NewestPoseTangentFromBody() const = 0;
  // Odometry time of the state at the previous scan's end, and the estimate T_mr at times `t`
  // within [previous, newest] for a dense trajectory between the scan poses: GP interpolation
  // between the knots around each time (SPEC §2) for the GP pipelines; for the baseline the IMU
  // propagated from the previous state and anchored at the newest, as its deskewing does.
  virtual double previous_time() const = 0;
  virtual std::vector<SE3> PosesSincePrevious(const std::vector<double>& t) const = 0;
  // The dense trajectory from the final estimates (final_trajectory.h): the times of the states
  // in the window, oldest first. SealOldest is called right before the window marginalises the
  // oldest state, whose estimate is final then: it keeps that final value and returns T_mr at `t`
  // (ascending, in (s, oldest] for the state s sealed before it) on the segment between the two,
  // both ends at their final values, by the same motion model as PosesSincePrevious (the
  // baseline's propagation anchored at both ends); at the oldest's time its pose exactly.
  // UnsealedPoses: the same over the segments from the state sealed last through the window's
  // states, from their current estimates (final once no scan follows), at `t` in (s, newest].
  virtual std::vector<double> StateTimes() const = 0;
  virtual std::vector<SE3> SealOldest(const std::vector<double>& t) = 0;
  virtual std::vector<SE3> UnsealedPoses(const std::vector<double>& t) const = 0;

  // How an IMU gap is bridged (for the scan's status message).
  virtual std::string ImuGapRecovery() const = 0;

  // The IMU residual blocks the last AddState added (imu_consistency.h), for their χ² after the
  // solve; empty for a pipeline without IMU terms.
  virtual const ImuTermBlocks& NewestImuBlocks() const { return no_imu_blocks_; }

 private:
  ImuTermBlocks no_imu_blocks_;
};

// The estimator of config.method. `imu` is the odometry's buffer (read only).
std::unique_ptr<Estimator> MakeEstimator(const OdometryConfig& config, const ImuBuffer& imu);

}  // namespace ctlio::lio
