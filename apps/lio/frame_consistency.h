// Lidar–IMU frame consistency (issue 40; docs/user-guide/bad-input.md, "Lidar–IMU frame
// consistency"): does the IMU measure in the frame the lidar trajectory says it is in?
//
// Two fits over the run, from the poses the lidar registered and the first IMU's raw samples:
//  - Specific force. Over a window of three scan poses about 1 s apart (those between only carry
//    the attitude), twice the second divided difference of
//    the IMU's positions equals the hat-weighted mean of its acceleration (the B-spline identity
//    2·p[t₀, t_m, t₂m] = ∫ M(s) p̈(s) ds, M the normalised hat on [t₀, t₂m]), and p̈ = R(s)·f(s) + g.
//    With R(s) the window's attitude carried between poses by the gyro (its bias removed per
//    interval against the pose's rotation), each window gives 3 equations linear in a 3×3 map M
//    (f ↦ M·f) and g (free: the map frame's tilt is a gauge of the lidar's data). Fitted with M = I
//    and with M free. The statistic is the residual RMS of M = I: a sign-flipped or axes-swapped
//    accelerometer (M = −I or a signed permutation) leaves the lidar's positions unexplained even
//    where the fused estimate tilts so that gravity explains the reading (which fools the IMU
//    terms' χ², run_checks.h); the free M names the defect when it is clear.
//  - Rotation. Over spans of scans, the rotation vector of the pose's relative rotation against
//    the gyro's integrated one: θ_pose ≈ θ_gyro + δ × θ_gyro − T·b (δ: the rotation between the
//    frame the gyro measures in and the one the poses put it in — a wrong extrinsic rotation —,
//    b: the gyro bias), linear in δ and b. δ is judged along the directions the rotation excited.
// Both are reported (evaluation.txt, summary) and warned about above measured thresholds.
#pragma once

#include <cstdint>
#include <deque>
#include <ostream>
#include <string>

#include "ctlio/factors/imu/imu_data.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio::lioapp {

struct FrameConsistencyOptions {
  // Windows [t₀, t₂m] with t_m the first pose ≥ t₀ + half_window_s and t₂m the first ≥ t_m +
  // half_window_s; a new window starts at every pose. The lidar's position jitter enters the
  // divided difference amplified ∝ 1/h²: a clean walking run with a VLP-16 gave 0.51 m/s² at
  // h = 0.3 s, 0.10 at 0.6 s and 0.031 at 1.0 s, while the defects' residual changed little.
  double half_window_s = 1.0;
  double rotation_span_s = 0.5;
  int min_windows = 15;  // fewer windows (or spans) are not judged (a 4 s run has ~18 windows)
  // Warn when the residual RMS of M = I exceeds this [m/s² per component]. Measured (simulated,
  // 12 setups x 2 indices, both methods; docs/user-guide/bad-input.md): clean runs 0.002–0.139
  // (walking with the units' effects; a clean baseline run that went wrong 0.154), a flipped or
  // swapped accelerometer 0.037–3.1, 103 of 144 above 0.15 (every miss in the box world). No
  // per-run noise floor measured (F-test, short-window jitter, accelerometer dynamics) separated
  // the box misses from the clean walking runs.
  double max_identity_rms = 0.15;
  // Rotation: warn when |δ| along the excited directions exceeds this [deg]; an axis is excited
  // when δ's information along it (Σ over spans of the rotation about the other axes, bias
  // eliminated) reaches min_rotation_excitation [rad²]. Measured: clean ≤ 1.28° (the probe's seed
  // 13 sequence; 0.91 in the 8 s set), 5° off 1.85–6.4°.
  double max_rotation_deg = 2.0;
  double min_rotation_excitation = 0.05;
};

struct FrameConsistency {
  int windows = 0;              // specific-force windows fitted
  double identity_rms = 0.0;    // m/s², residual RMS per component with M = I (g free)
  double free_rms = 0.0;        // with M free
  double cpu_ms = 0.0;          // thread CPU time spent in the check over the run
  double explained = 0.0;       // (SS_I − SS_free) / SS_I (diagnostic)
  Mat3 map = Mat3::Identity();  // the fitted M
  double map_deviation = 0.0;   // |M − I|_F
  std::string map_reading;      // "(-x, -y, -z)": M's nearest signed permutation, or "" if none
  // The signed permutation P ≠ I (one of the 47 other labellings of the accelerometer's axes, no
  // free parameter, g refitted) that explains the positions best, and its residual RMS.
  std::string best_relabelling;
  double best_relabelling_rms = 0.0;
  int rotation_spans = 0;
  Vec3 rotation_error = Vec3::Zero();  // δ [rad], along the excited directions only
  int excited_axes = 0;
  Vec3 rotation_excitation = Vec3::Zero();  // eigenvalues of δ's information [rad²], ascending
  Vec3 rotation_error_all = Vec3::Zero();   // δ on all axes (the unexcited ones poorly known)
  double rotation_rms_deg = 0.0;            // residual RMS per span component after the fit
  std::string warning;                      // empty when consistent or not judged
};

// evaluation.txt lines: frame_windows, frame_map_explained, frame_map_deviation, frame_map (M row
// by row), frame_rotation_spans, frame_rotation_excited_axes, frame_rotation_error_deg and, when
// warned, frame_inconsistency "…". Nothing when no window or span was fitted.
void WriteFrameConsistency(const FrameConsistency& r, std::ostream& out);

class FrameConsistencyCheck {
 public:
  // `clock_offset_s`: the IMU's configured clock offset δ (calibration.time_offset_s): a sample
  // stamped t on the IMU's clock is placed at t + δ on the lidar's (calibration_options.h), as the
  // estimator places it. Without it a configured offset reads as a frame defect: 20 ms at the fast
  // regime's 2 rad/s is a 2.3° rotation between the gyro's spans and the poses'.
  explicit FrameConsistencyCheck(const SE3& T_robot_imu = SE3(), int imu = 0,
                                 const FrameConsistencyOptions& options = {},
                                 double clock_offset_s = 0.0);
  // The samples of every IMU, in time order (others than `imu` are ignored).
  void AddImu(const imu::ImuSample& sample);
  // A pose the lidar registered (status ok), in time order; T_mr of the robot frame.
  void AddPose(int64_t t_ns, const SE3& T_mr);
  // A scan the lidar did not fix breaks the chain of poses: windows do not span it.
  void Break();
  FrameConsistency Result() const;

 private:
  struct Pose {
    int64_t t_ns;
    SE3 T_mi;  // the IMU's pose
  };
  void Process();
  size_t After(size_t from, double span) const;
  void Window(size_t first, size_t center, size_t end);
  void RotationSpan(size_t first, size_t end);

  SE3 T_ri_;
  int imu_;
  FrameConsistencyOptions options_;
  int64_t clock_offset_ns_;
  std::deque<imu::ImuSample> samples_;
  std::deque<Pose> poses_;
  size_t next_window_ = 0, next_span_ = 0;  // index in poses_ of the next window's / span's first
  // Normal equations of the specific-force fit, x = [vec(M); g], and of the rotation fit,
  // y = [δ; b].
  Eigen::Matrix<double, 12, 12> N_ = Eigen::Matrix<double, 12, 12>::Zero();
  Eigen::Matrix<double, 12, 1> v_ = Eigen::Matrix<double, 12, 1>::Zero();
  double s_ = 0.0;
  int windows_ = 0;
  Mat6 Nr_ = Mat6::Zero();
  Vec6 vr_ = Vec6::Zero();
  double sr_ = 0.0;
  double cpu_ms_ = 0.0;
  int spans_ = 0;
};

}  // namespace ctlio::lioapp
