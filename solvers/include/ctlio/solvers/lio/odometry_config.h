// Configuration and input/output types of the lidar-inertial odometry pipelines (SPEC §4–§6):
// Singer-LIO (IMU as a measurement; lidar_gyro and lidar_only variants) and the IMU-as-input
// baseline. data/sim_lio.yaml and data/newer_college_lio.yaml document every key.
//
// Frames: the robot frame r IS the IMU frame; lidar points are moved into it with the extrinsic
// T_imu_lidar on arrival. The map frame m is the robot frame at the first scan's start, and
// C_mi rotates the gravity-aligned frame i (g_i = [0, 0, −g]) into m (gravity initialisation).
// Times: int64 ns at the interface (SPEC §1), double seconds relative to the first scan inside.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/factors/imu/imu_data.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"
#include "ctlio/solvers/lio/calibration_options.h"
#include "ctlio/solvers/lio/degeneracy.h"
#include "ctlio/solvers/lio/input_check_options.h"
#include "ctlio/solvers/lio/knot_spacing.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"
#include "ctlio/solvers/lio/sweep_keypoint_budget.h"

namespace YAML {
class Node;
}

namespace ctlio::lio {

// Upper bound of imu.input_substeps (each substep is one preintegration step).
inline constexpr int kMaxInputSubsteps = 16;

enum class LioMethod {
  kSingerLio,  // GP (Singer) prior, lidar + gyro + accelerometer as measurements, biases
  kLidarGyro,  // same without the accelerometer
  kLidarOnly,  // GP prior + lidar only
  kImuInput,   // baseline: preintegrated IMU between scan-time states, IMU-integrated deskew
};
LioMethod ParseLioMethod(const std::string& name);  // throws std::invalid_argument
std::string LioMethodName(LioMethod method);

struct OdometryConfig {
  LioMethod method = LioMethod::kSingerLio;
  LidarFrontendOptions frontend;

  // --- GP prior (Singer), per axis in [ρ; φ] order (SPEC §2, §4). Qc per second.
  Vec6 qc = (Vec6() << 5000, 5000, 5000, 500, 500, 500).finished();
  Vec6 alpha = (Vec6() << 0, 0, 0, 100, 100, 100).finished();

  // --- IMU noise (SPEC §4 defaults: the paper's Newer College values).
  double accel_variance = 0.156;  // (m/s²)², whitened error under a Cauchy loss
  double accel_loss_scale = 1.0;  // Cauchy scale on the whitened accelerometer error; 0 = none
  // imu.accel_loss_relax_bias_sigma [m/s²], imu.accel_loss_relaxed_scale (Singer-LIO;
  // accel_loss_schedule.h): once the window's marginal σ of the accelerometer bias (largest axis)
  // is below the first, every later interval takes the second as its Cauchy scale (0: no loss).
  // 0 = off: accel_loss_scale all run long.
  double accel_loss_relax_bias_sigma = 0.0;
  double accel_loss_relaxed_scale = 0.0;
  double gyro_variance = 4.326e-4;  // (rad/s)²
  // Bias random walk: variance accumulated per `bias_walk_period` seconds (the paper's per 0.1 s);
  // scaled by Δt between knots (SPEC §3) — the reference code does not scale it.
  double bias_accel_walk = 1.1236e-2;
  double bias_gyro_walk = 1.6e-4;
  double bias_walk_period = 0.1;
  double initial_bias_accel_variance = 0.1;
  double initial_bias_gyro_variance = 0.01;
  double gravity = 9.81599;
  // Exact specific force (with ω×v; the default) or, false, the paper's approximation (the
  // body-centric accelerometer model without ω×v, imu::AccelModel::kBodyCentric).
  bool exact_specific_force = true;
  // IMU-input baseline: per-sample standard deviations of the IMU at imu_rate_hint; the
  // preintegration uses the continuous densities σ/√rate.
  double input_accel_sigma = 0.02;  // m/s², per sample at rate_hint
  double input_gyro_sigma = 0.01;   // rad/s, per sample at rate_hint
  double imu_rate_hint = 200.0;     // Hz, for the densities above
  // IMU-input baseline: each held segment of the preintegration takes the IMU signal interpolated
  // at its midpoint (imu_midpoint.h; the default: a sample is the rate at its stamp, so holding it
  // over the following period integrates it half a period late, an error the noise model does
  // not describe: docs/experiments/covariance.md), or, false, the paper's zero-order hold (each
  // sample held from its stamp to the next).
  bool input_midpoint = true;
  // IMU-input baseline, with input_midpoint: how the signal between samples is read. "linear"
  // (the default) takes the line through the two samples around a segment's midpoint; "cubic"
  // the cubic through the four around it (two each side; the line where the stream has fewer),
  // and each sample period is integrated in `input_substeps` equal parts, each at its own
  // midpoint. The line's mean over a period is off by Δt²/12·f̈ and a constant rate per period
  // drops the rotation's coupling within it (coning and sculling, O(Δt²)): in fast motion at
  // 200 Hz they biased the lever arm by +1.6 / +1.4 cm (y / z), which cubic with 4 substeps
  // removes (docs/experiments/calibration.md, "The baseline's fast lever-arm bias").
  std::string input_interpolation = "linear";  // linear | cubic
  int input_substeps = 1;                      // [1, kMaxInputSubsteps]
  // IMU-input baseline across an IMU gap (no preintegration there): the velocity is a random
  // walk with this variance per second [(m/s)²/s] between the states around the gap.
  double gap_velocity_walk = 4.0;
  // Holes in the IMU up to this length [s] are still preintegrated, holding the last sample (a
  // few missing samples: the hold's error grows with the square of the hole); only longer holes
  // switch to the gap mode above, where the hold diverges (docs/experiments/imu-dropout.md).
  double gap_hold_max = 0.1;
  // The earlier behaviour, kept to measure against: preintegrate across the gap holding the last
  // sample (zero-order hold).
  bool gap_zero_order_hold = false;
  // imu.residual_blocks (Singer-LIO, lidar_gyro): "interval", one residual block per knot
  // interval and IMU holding all its samples' gyro and accelerometer residuals, each sample's
  // accelerometer loss applied inside (imu/imu_interval_batch.h); or "sample", a gyro and an
  // accelerometer block per sample. The same cost, gradient and Gauss–Newton step up to rounding
  // (docs/experiments/imu-batch.md).
  std::string imu_residual_blocks = "interval";

  // (The lidar residual's standard deviation is frontend.point_noise_sigma: the planarity-weighted
  // point-to-plane error is divided by it, and the loss scale stays in metres.)

  // --- Initialisation and robustness.
  double gravity_init_duration = 0.2;  // s of accelerometer averaged while still at start
  // "Still enough" (imu::InitializeGravity): largest deviation of a 0.1 s block mean of the
  // accelerometer from the overall mean.
  double gravity_init_max_std = 0.4;  // m/s²
  // A scan whose keypoints produce fewer than this many plane associations is degenerate: the
  // lidar term is dropped for it (the prior + IMU carry the state) and the scan is flagged.
  int min_associations = 50;
  double max_imu_gap = 0.05;  // s; a longer hole in the IMU stream is reported per scan
  // A scan is a failure if the pose jumps more than this between consecutive scans (m).
  double max_scan_translation = 5.0;
  // Degenerate directions of the lidar term per scan (YAML section `degeneracy`, degeneracy.h):
  // logged; lidar_only keeps the prediction along them and reports the scan degenerate.
  DegeneracyOptions degeneracy;

  // --- Window and solver.
  int window_knots = 2;  // newest knots kept free (SPEC §4: 2, the one before held)
  // window.knots_per_scan (the GP methods; the baseline's states stay one per scan): K knots per
  // sweep, at the sweep's end and at K − 1 equally spaced times inside it, so the trajectory
  // between knots spans 1/K of a sweep (with 0.1 s sweeps, the fast regime's 4–8 Hz motion is
  // interpolated coarsely; docs/experiments/calibration.md). The lidar residuals, IMU measurements,
  // motion prior and bias walk go to the interval that holds their time; after the scan the
  // window marginalises down to window_knots − 1 knots as before. 1 = the paper's knot per scan.
  int knots_per_scan = 1;
  // window.adaptive_knots_max, window.adaptive_knots_gyro_curvature [rad/s],
  // window.adaptive_knots_accel_curvature [m/s²] (the GP methods; knot_spacing.h): a sweep whose
  // gyro (accelerometer) samples leave an RMS residual r above the threshold about their straight
  // line in time gets the fewest K ≤ adaptive_knots_max knots with r / K² ≤ threshold, so the
  // knot spacing follows the motion (handheld shaking) rather than the sensor. Off by default in
  // code (max ≤ knots_per_scan); data/sensors/base.yaml sets it (docs/experiments/knot-spacing.md).
  // window.adaptive_knots_accel_variance, _gyro_variance: the IMU variances' floor on the sweeps
  // the rule splits (AdaptiveKnotOptions).
  AdaptiveKnotOptions adaptive_knots;
  // window.slow_sweep_max_keypoints, window.slow_sweep_speed [m/s] (the GP methods;
  // sweep_keypoint_budget.h): an unsplit sweep whose estimated speed is below the threshold gets
  // its own keypoint budget (walking against driving). Off by default in code (0).
  SlowSweepKeypoints slow_sweep_keypoints;
  // window.threads: the solve's interpolations and lidar rows (SlidingWindowOptions::threads);
  // Ceres evaluates on one thread (iterations per round: lidar_frontend.solver_iterations)
  int solver_threads = 1;
  // window.overlap: scan k's voxel-map insertion and the marginalisation before scan k+1 run on a
  // second thread, instead of one after the other on the scan thread: the insertion from the
  // moment scan k's pose is estimated (in real time it ends while the robot waits for the next
  // sweep), the marginalisation beside scan k+1's range gate and subsampling (neither reads what
  // the other writes). The same estimates, bit for bit.
  bool overlap_stages = false;
  bool estimate_gravity = false;  // hold C_mi after initialisation (paper) or refine it
  // window.imu_prediction (the GP methods): a new knot starts from the previous one carried
  // through the interval's IMU samples (imu_knot_prediction.h: ϖ_ω from each gyro sample, ϖ̇_v
  // from each accelerometer sample, integrated), instead of constant body velocity with ϖ̇ = 0.
  // Only the solver's starting point changes, not the problem.
  bool imu_prediction = false;
  // window.gap_prediction_span (the GP methods) [s]: a knot whose interval has no IMU sample (an
  // IMU outage) starts from the previous knot moved by the mean twist of the estimate over the
  // last gap_prediction_span seconds, Log(T_k·T_{k−span}⁻¹)/span, with ϖ̇ = 0; 0: the previous
  // knot's own ϖ (constant body velocity). The mean follows travel but not vibration: in the
  // fast regime ϖ swings ±1–2 rad/s at 4–8 Hz, and carried through a 0.1 s sweep from the last
  // knot it started the solve ~10° off, where the sparse lidar lost the scan. 1 s: fast-regime
  // 1 s outages bridged (0.5 s and 2 s worse on the VLP-16-like sensor: 2.9 and 0.28 m against
  // 0.17 m; docs/experiments/imu-batch.md). Only the solver's starting point changes.
  double gap_prediction_span = 1.0;

  // --- Sensor setup.
  SE3 T_imu_lidar;  // lidar → robot (IMU) frame

  // --- Plausibility gates on the input (input_checks.h), applied by LioOdometry; YAML `input:`.
  InputCheckOptions input;

  // --- Several IMUs (top-level YAML key `imus`, or the dataset's IMUs; ImuSample::imu indexes
  // the list). Empty: one IMU whose frame is the robot frame, with the variances above. Otherwise
  // IMU j sits at T_robot_imu (imu_mounting.h) and has its own variances (0 = the `imu`
  // section's), its own bias states and their random walk (the `imu` section's parameters).
  // Singer-LIO and lidar_gyro take every sample of every IMU as a measurement; the IMU-as-input
  // baseline preintegrates one IMU, `input_imu` (imu.input_imu), rotated into the robot frame
  // (its lever arm is not modelled: that would need the derivative of the gyro).
  struct ImuSensor {
    SE3 T_robot_imu;
    double accel_variance = 0.0;  // (m/s²)²
    double gyro_variance = 0.0;   // (rad/s)²
  };
  std::vector<ImuSensor> imus;
  int input_imu = 0;
  int num_imus() const { return imus.empty() ? 1 : static_cast<int>(imus.size()); }
  // The mounting and the sample variances of IMU j.
  SE3 ImuPose(int j) const { return imus.empty() ? SE3() : imus[j].T_robot_imu; }
  double AccelVariance(int j) const;
  double GyroVariance(int j) const;

  // Consistency: after every scan, the covariance of the newest pose (ceres::Covariance of the
  // window at the solution) into ScanResult::pose_covariance (window.pose_covariance). Off by
  // default: it costs one more Jacobian evaluation and a factorisation per scan.
  bool pose_covariance = false;
  // The lidar residuals' variance in that covariance only, as a multiple of point_noise_sigma²
  // (window.pose_covariance_lidar_scale; the estimate is unchanged). 1: the window as solved
  // (ceres::Covariance); else its dense Gauss–Newton information with the newest scan's lidar
  // blocks divided by it (ScaledPoseCovariance). For a lidar σ that weighs the estimate well but
  // overstates the pose's spread (docs/experiments/covariance.md).
  double pose_covariance_lidar_scale = 1.0;
  // window.pose_covariance_adaptive: the covariance with each noise group's variance estimated
  // from its own residuals at every scan (adaptive_covariance.h; the estimate is unchanged;
  // overrides pose_covariance_lidar_scale): the lidar's from the robust spread of its
  // point-to-plane residuals, inflated by pose_covariance_lidar_neff for the errors its residuals
  // share (map planes, deskewing) that the pose absorbs and the spread cannot show; the IMU
  // terms' by variance components; the marginal prior's alike.
  bool pose_covariance_adaptive = false;
  double pose_covariance_lidar_neff = 10.0;
  // window.pose_covariance_lidar_floor_m / _rad: an error floor of the scan's lidar term, σ of a
  // rigid misregistration of the whole scan (per axis, robot frame) that its keypoints share and
  // do not average out (lidar_floor_covariance.h; with pose_covariance_lidar_scale, the point
  // noise's part; not with pose_covariance_adaptive). 0 and 0: no floor. Applied where the lidar
  // term is on one pose (the IMU-as-input baseline); the estimate is unchanged.
  double pose_covariance_lidar_floor_m = 0.0;
  double pose_covariance_lidar_floor_rad = 0.0;
  // window.pose_covariance_map_sigma_m / _rad: σ per axis (map frame) of the map's own error, a
  // rigid error of the map that every later scan, registered against it, inherits: added to the
  // reported covariance (lidar and the IMU, whose gravity is held in the map frame, measure the
  // pose relative to the map only, so the posterior of T_mr is that relative to the map plus the
  // map's, Σ = Σ_rel + Σ_map in ε). For an estimate whose start-up error stays in the map
  // (sparse sensors; docs/experiments/covariance.md). 0 and 0: none. The estimate is unchanged.
  double pose_covariance_map_sigma_m = 0.0;
  double pose_covariance_map_sigma_rad = 0.0;
  // window.pose_covariance_map_growth g: the map's error as it was built, added to the reported
  // covariance — each scan moves the map by the fraction of the map's points it inserts times its
  // own relative error, Σ_map += g·β²·Σ_rel (map_growth_covariance.h; 1 = the model as derived).
  // For sparse sensors whose start-up error stays in the map (docs/experiments/covariance.md,
  // "16 beams"). 0: none. The estimate is unchanged.
  double pose_covariance_map_growth = 0.0;
  // window.pose_covariance_misfit: where the newest interval's IMU χ² rejects the motion model
  // (above its 99.9 % quantile and its dof), the covariance gains what that model's information
  // was worth, the model's variance scaled by χ²/dof (misfit_covariance.h; before the map's error,
  // so the map growth carries it). The estimate is unchanged.
  bool pose_covariance_misfit = false;

  // How many of the newest ScanResults results() keeps (LioOdometry, CalibratingOdometry; 0:
  // every one). Bounded so that the pipeline's memory does not grow with the length of the run
  // (~1.1 kB a result and its notes); the odometry itself never reads them. Not a YAML key: a
  // property of the caller.
  size_t kept_results = 100;

  // --- Online lidar–IMU calibration (top-level YAML section `calibration`, calibration_options.h;
  // Singer-LIO and lidar_gyro): time offset per IMU and extrinsic T_imu_lidar as estimated states.
  CalibrationOptions calibration;

  // --- Per-method overrides (YAML key `per_method`): the complete configuration to use when
  // running that method, i.e. this one with the override's keys replaced. One file can so
  // hold values tuned for Singer-LIO and for the IMU-as-input baseline side by side. Each entry
  // is resolved when the file is read: a field changed in code afterwards must be changed in the
  // entries too, or ForMethod of an overridden method runs the file's value.
  std::map<LioMethod, std::shared_ptr<const OdometryConfig>> per_method;
  // The configuration that runs `m`: its override if there is one, else this one; `method` = m.
  OdometryConfig ForMethod(LioMethod m) const;

  void Validate() const;  // throws std::invalid_argument naming the bad field
};

// Reads a YAML file: top-level keys `method`, `gp`, `imu`, `init`, `window`, `extrinsic`,
// `lidar_frontend`, `degeneracy`, `input`, `imus`, `calibration` and `per_method`. Missing keys
// keep their defaults; unknown keys and bad values throw std::runtime_error naming file and line.
// `per_method` maps a method name (singer_lio, lidar_gyro, lidar_only, imu_input) to sections `gp`,
// `imu`, `init`, `window`, `lidar_frontend` whose keys replace the base values for that method only
// (same keys, same checks; `method`, `extrinsic`, `input`, `imus` and `calibration` — properties of
// the data — cannot be set per method):
//   lidar_frontend: {max_iterations: 3}
//   per_method:
//     imu_input: {lidar_frontend: {max_iterations: 5}}
OdometryConfig OdometryConfigFromYaml(const YAML::Node& root, const std::string& source);
// Reads an odometry config file or composition (LoadOdometryYaml) and converts it.
OdometryConfig LoadOdometryConfig(const std::string& path);

// Reads an odometry config as YAML: one file, or a comma-separated list "a.yaml,b.yaml" whose later
// files win key by key (config_composition.h). A top-level `base: PATH` or `base: [PATH, ...]`
// (relative to the file's folder) makes a file extend others the same way: the bases are read and
// checked first (their errors name their own file and line), then the file's keys replace theirs
// mapping by mapping — a key inside a section replaces that key only, a value or a list replaces
// the whole value — and the result has no `base` key. Up to 8 files deep (a cycle is reported as
// too deep); a base must be a regular file. data/sim_lio_calibration.yaml is data/sim_lio.yaml
// with the overlay data/calibration.yaml this way.
YAML::Node LoadOdometryYaml(const std::string& path);

// --- Pipeline input (what a dataset reader or the simulator hands over, converted by the app).
// IMU samples are the IMU library's (robot = IMU frame).
using ImuSample = imu::ImuSample;

struct LidarScan {
  int64_t begin_ns = 0;           // first firing
  int64_t end_ns = 0;             // last firing: the knot time of this scan
  std::vector<Vec3> points;       // lidar frame
  std::vector<int64_t> times_ns;  // absolute per-point times, same size as points
};

// --- Pipeline output, one per scan.
// kSuspect: estimated, but from input that cannot be right (the IMU output stayed bit-identical
// while the lidar moved: a frozen or dead IMU, input_checks.h); not to be trusted.
enum class ScanStatus { kOk, kInitialising, kDegenerate, kImuGap, kFailed, kSuspect };
const char* ScanStatusName(ScanStatus status);

struct ScanResult {
  int64_t t_ns = 0;              // scan end (knot time)
  SE3 T_mr;                      // robot pose in the map (T_rm⁻¹) at t_ns
  Vec6 velocity = Vec6::Zero();  // [v; ω] body frame (Singer: −ϖ; baseline: C_rmᵀ v_m)
  Vec6 bias = Vec6::Zero();      // [b_a; b_g] (of IMU 0)
  std::vector<Vec6> imu_biases;  // [b_a; b_g] of every IMU (Singer-LIO, lidar_gyro)
  // With OdometryConfig::pose_covariance: Σ of ε in T_mr(true) = Exp(ε)·T_mr (6×6, [ρ; φ]).
  bool has_pose_covariance = false;
  Mat6 pose_covariance = Mat6::Zero();
  ScanStatus status = ScanStatus::kOk;
  std::string message;  // why, for anything but kOk; also the input gates' notes (below)
  // Input gates (input_checks.h): IMU samples rejected since the previous scan (beyond the
  // physical range or not finite), points dropped for a time outside the scan's interval.
  int imu_rejected = 0;
  int points_dropped = 0;
  int keypoints = 0;
  int associations = 0;  // lidar residuals in the final round
  int imu_residuals = 0;
  int rounds = 0;  // re-association rounds
  // Translation [m] of the estimate away from the prediction it started from (the GP's
  // extrapolation or the baseline's preintegration); 0 for the initialising scan.
  double correction_m = 0.0;
  double correction_rad = 0.0;  // the rotation angle of the same correction
  int solver_iterations = 0;
  double final_cost = 0.0;
  // Whitened χ² (no robust loss) of the IMU terms this scan added, at its final estimate, and
  // their residual components (imu_consistency.h): χ²/dof ≈ 1 when the IMU agrees with the lidar
  // and its noise setting is right. Singer-LIO: accelerometer and gyro; lidar_gyro: gyro; the
  // baseline: its preintegrated factor (9 components) as accel. 0 without IMU terms.
  double accel_chi2 = 0.0;
  int accel_dof = 0;
  double gyro_chi2 = 0.0;
  int gyro_dof = 0;
  // Singer-LIO with imu.accel_loss_relax_bias_sigma (accel_loss_schedule.h), IMU 0: this scan's
  // accelerometer residuals took the relaxed scale, and the largest σ of the accelerometer bias
  // [m/s²] the schedule read before the scan (0 once relaxed, or with the schedule off).
  bool accel_loss_relaxed = false;
  double accel_bias_sigma = 0.0;
  double milliseconds = 0.0;    // wall time of this scan, split into:
  double ms_preprocess = 0.0;   // range gate, subsampling, keypoints
  double ms_associate = 0.0;    // interpolation + kNN + plane fits, all rounds
  double ms_solve = 0.0;        // Ceres, all rounds
  double ms_map = 0.0;          // deskew + map insertion
  double ms_marginalize = 0.0;  // Schur complement of the leaving knot
  // Degenerate directions of this scan's lidar term (degeneracy.h); analysed = false when the
  // scan was not registered or the analysis is off.
  DegeneracyReport degeneracy;
  // CPU time of this scan's thread (CLOCK_THREAD_CPUTIME_ID): unlike the wall times above it
  // does not grow when other processes share the cores.
  double cpu_ms = 0.0;
  // Earlier scans whose results this scan replaced (calibration.warmup_replay_s): that many
  // entries before this one in CalibratingOdometry::results() now hold the replayed estimates; a
  // caller that kept the earlier results re-reads them. 0 for every other scan.
  int revised_scans = 0;
  // Online calibration (OdometryConfig::calibration) after this scan: the estimates and their
  // marginal σ (the window's pseudo-inverse). Empty / false when not estimated.
  struct CalibrationEstimate {
    std::vector<double> time_offset_s;        // δ_j per IMU [s]
    std::vector<double> time_offset_sigma_s;  // marginal σ of δ_j [s]
    bool has_extrinsic = false;
    SE3 T_imu_lidar;
    Vec6 extrinsic_sigma = Vec6::Zero();  // marginal σ, [ρ; φ] (m, rad)
    // Observability from the measurements alone (calibration_observability.h), per coordinate
    // [δ_0 … δ_{J−1}, then ρ_x, ρ_y, ρ_z, φ_x, φ_y, φ_z with the extrinsic]; empty when not
    // assessed (calibration.observability_horizon_scans = 0, the initialising scan).
    std::vector<double> observability;  // ν over the horizon after this scan (whitened)
    std::vector<bool> unobservable;     // ν < threshold: held during the next scan's solve
    std::vector<bool> held;             // held during this scan's solve
  } calibration;
};

}  // namespace ctlio::lio
