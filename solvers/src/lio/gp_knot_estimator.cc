#include "ctlio/solvers/lio/gp_knot_estimator.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "ctlio/solvers/lio/bias_priors.h"
#include "ctlio/solvers/lio/calibration_blocks.h"
#include "ctlio/solvers/lio/continuous_lidar_term.h"
#include "ctlio/solvers/lio/imu_knot_prediction.h"
#include "ctlio/solvers/lio/knot_spacing.h"
#include "ctlio/solvers/lio/sweep_keypoint_budget.h"

namespace ctlio::lio {

GpKnotEstimator::GpKnotEstimator(const OdometryConfig& config, const ImuBuffer& imu)
    : config_(config),
      imu_(imu),
      model_(config.qc, config.alpha),
      accel_loss_(config.accel_loss_scale,
                  config.method == LioMethod::kSingerLio ? config.accel_loss_relax_bias_sigma : 0.0,
                  config.accel_loss_relaxed_scale, config.num_imus()) {
  for (int j = 0; j < config_.num_imus(); ++j) {
    mountings_.push_back(imu::ImuMounting::FromPose(config_.ImuPose(j)));
  }
  const CalibrationOptions& cal = config_.calibration;
  time_offsets_ = cal.estimate_time_offset;
  for (double d : cal.time_offset_s) time_offsets_ = time_offsets_ || d != 0.0;
  if (!cal.time_offset_s.empty() && static_cast<int>(cal.time_offset_s.size()) < num_imus()) {
    throw std::invalid_argument(
        "calibration.time_offset_s: " + std::to_string(cal.time_offset_s.size()) + " values for " +
        std::to_string(num_imus()) + " IMUs");
  }
}

double GpKnotEstimator::TimeOffset(int imu, const SlidingWindow& window) const {
  return config_.calibration.estimate_time_offset ? window.State(TimeOffsetKey(imu))[0]
                                                  : config_.calibration.TimeOffset(imu);
}

GpKnotEstimator::Knot GpKnotEstimator::AddKnot(double t, const SE3& T_rm, const Vec6& w,
                                               const Vec6& dw, const std::vector<Vec6>& bias,
                                               SlidingWindow* window) {
  Knot k;
  k.t = t;
  k.keys = KnotKeys::ForKnot(next_knot_++);
  k.pose = window->AddPoseState(k.keys.pose, T_rm);
  k.velocity = window->AddVectorState(k.keys.velocity, w);
  k.acceleration = window->AddVectorState(k.keys.acceleration, dw);
  for (int j = 0; j < num_imus(); ++j) {
    k.bias.push_back(window->AddVectorState(k.keys.Bias(j), bias[j]));
  }
  return k;
}

namespace {

std::vector<StateId> KeysOf(const KnotKeys& keys, size_t num_bias) {
  std::vector<StateId> out = keys.Motion();
  for (size_t j = 0; j < num_bias; ++j) out.push_back(keys.Bias(static_cast<int>(j)));
  return out;
}

}  // namespace

std::vector<StateId> GpKnotEstimator::OldestKeys() const {
  return KeysOf(knots_.front().keys, knots_.front().bias.size());
}

std::vector<StateId> GpKnotEstimator::NewestKeys() const {
  // Every knot the last scan added: their factors are the scan's interval.
  std::vector<StateId> out;
  const size_t n = std::clamp<size_t>(static_cast<size_t>(scan_knots_), 1, knots_.size());
  for (size_t i = knots_.size() - n; i < knots_.size(); ++i) {
    const std::vector<StateId> keys = KeysOf(knots_[i].keys, knots_[i].bias.size());
    out.insert(out.end(), keys.begin(), keys.end());
  }
  return out;
}

size_t GpKnotEstimator::ScanStartIndex() const {
  return knots_.size() - 1 - std::min(static_cast<size_t>(scan_knots_), knots_.size() - 1);
}

SE3 GpKnotEstimator::PoseSinceScanStart(double tau) const {
  size_t j = ScanStartIndex();
  while (j + 2 < knots_.size() && tau > knots_[j + 1].t) ++j;
  return PoseAt(knots_[j], knots_[j + 1], tau);
}

GpKnotEstimator::TimedState GpKnotEstimator::ValueOf(const Knot& k) {
  return {k.t, gp::ReadKnotState(k.pose, k.velocity, k.acceleration)};
}

SE3 GpKnotEstimator::PoseAt(const Knot& a, const Knot& b, double tau) const {
  return PoseBetween(ValueOf(a), ValueOf(b), tau);
}

SE3 GpKnotEstimator::PoseBetween(const TimedState& a, const TimedState& b, double tau) const {
  const gp::GpInterpolator interp(model_, a.t, b.t, std::clamp(tau, a.t, b.t));
  SE3 T_rm;
  interp.Pose(a.x, b.x, &T_rm, nullptr, nullptr);
  return T_rm.Inverse();
}

std::vector<SE3> GpKnotEstimator::PosesOver(const std::vector<TimedState>& chain,
                                            const std::vector<double>& t) const {
  std::vector<SE3> poses;
  poses.reserve(t.size());
  size_t j = 0;  // the first knot at or after τ (or the last)
  for (const double tau : t) {
    while (j + 1 < chain.size() && chain[j].t < tau) ++j;
    poses.push_back(j == 0 || tau >= chain[j].t ? chain[j].x.pose.Inverse()
                                                : PoseBetween(chain[j - 1], chain[j], tau));
  }
  return poses;
}

std::vector<double> GpKnotEstimator::StateTimes() const {
  std::vector<double> t;
  for (const Knot& k : knots_) t.push_back(k.t);
  return t;
}

std::optional<Vec6> GpKnotEstimator::MeanTwist(const Knot& prev) const {
  const double span = config_.gap_prediction_span;
  if (span <= 0.0) return std::nullopt;
  // The states before prev, newest first: the window's knots, then the sealed ones.
  const TimedState* ref = nullptr;
  const auto consider = [&](const TimedState& s) {
    if (s.t >= prev.t || (ref != nullptr && ref->t <= prev.t - span)) return;
    ref = &s;
  };
  std::vector<TimedState> window_states;
  for (const Knot& k : knots_) window_states.push_back(ValueOf(k));
  for (auto it = window_states.rbegin(); it != window_states.rend(); ++it) consider(*it);
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (it->t < knots_.front().t) consider(*it);  // not a stale copy of a window knot
  }
  if (ref == nullptr || prev.t - ref->t < 0.1 * span) return std::nullopt;
  const SE3 T_prev = PoseManifold::Pose(prev.pose);
  return Vec6((T_prev * ref->x.pose.Inverse()).Log() / (prev.t - ref->t));
}

std::vector<SE3> GpKnotEstimator::SealOldest(const std::vector<double>& t) {
  // Both knots' full GP states at their final values: the interpolation of the factors (SPEC §2)
  // between them is the final estimate of the interval.
  std::vector<TimedState> chain;
  if (sealed_) chain.push_back(*sealed_);
  chain.push_back(ValueOf(knots_.front()));
  std::vector<SE3> poses = PosesOver(chain, t);
  sealed_ = chain.back();
  return poses;
}

std::vector<SE3> GpKnotEstimator::UnsealedPoses(const std::vector<double>& t) const {
  std::vector<TimedState> chain;
  if (sealed_) chain.push_back(*sealed_);
  for (const Knot& k : knots_) chain.push_back(ValueOf(k));
  return PosesOver(chain, t);
}

SE3 GpKnotEstimator::NewestPose() const { return PoseManifold::Pose(knots_.back().pose).Inverse(); }

std::vector<SE3> GpKnotEstimator::PosesSincePrevious(const std::vector<double>& t) const {
  std::vector<SE3> poses;
  poses.reserve(t.size());
  for (const double tau : t) poses.push_back(PoseSinceScanStart(tau));
  return poses;
}

SE3 GpKnotEstimator::PreviousPose() const { return PoseManifold::Pose(ScanStart().pose).Inverse(); }

void GpKnotEstimator::Report(ScanResult* result) const {
  const Knot& k = knots_.back();
  if (time_offsets() && config_.calibration.estimate_time_offset && window_ != nullptr) {
    result->calibration.time_offset_s.clear();
    for (int j = 0; j < num_imus(); ++j) {
      result->calibration.time_offset_s.push_back(TimeOffset(j, *window_));
    }
  }
  result->T_mr = PoseManifold::Pose(k.pose).Inverse();
  // ϖ is minus the body twist [v; ω] in the robot frame (SPEC §1).
  result->velocity = -Eigen::Map<const Vec6>(k.velocity);
  result->bias = k.bias.empty() ? Vec6::Zero() : Vec6(Eigen::Map<const Vec6>(k.bias[0]));
  result->imu_biases.clear();
  for (const double* b : k.bias) result->imu_biases.push_back(Eigen::Map<const Vec6>(b));
  if (extrinsic_ != nullptr) {
    result->calibration.has_extrinsic = true;
    result->calibration.T_imu_lidar = PoseManifold::Pose(extrinsic_);
  }
}

void GpKnotEstimator::Initialise(const PreparedScan& scan, const Mat3& C_mi,
                                 SlidingWindow* window) {
  // Still at start (checked by the gravity initialisation): knot 0 is the map origin at rest.
  // Its pose, ϖ and ϖ̇ are held constant, which fixes the gauge; its biases are free under the
  // initial bias prior (zero mean, config variances), so the marginal priors carry them on.
  if (config_.method == LioMethod::kSingerLio) {
    window->AddRotationState(kGravityKey, C_mi);
    // With the extrinsic estimated, C_mi is refined too: the map frame is fixed by the first
    // scan's points, placed with the prior extrinsic, so a rotation error of the prior tilts the
    // map against the gravity C_mi was initialised with (in the robot frame); held, that tilt
    // would pull the extrinsic back to its prior through the accelerometer. Not in the held pass
    // of a warm-up replay (calibration.hold_gravity), which starts from the warm-up's estimates:
    // there a free C_mi costs accuracy (fast/100: ATE 0.59 held against 0.89 cm free).
    if (!config_.estimate_gravity && (!estimates_extrinsic() || config_.calibration.hold_gravity)) {
      window->SetStateConstant(kGravityKey, true);
    }
  }
  if (estimates_extrinsic()) {
    // T_rl: a static state with the Gaussian prior of the config (calibration_blocks.h).
    extrinsic_ = AddExtrinsicState(config_, window);
  }
  knots_.push_back(AddKnot(scan.t_end, SE3(), Vec6::Zero(), Vec6::Zero(),
                           std::vector<Vec6>(num_imus(), Vec6::Zero()), window));
  const Knot& k = knots_.back();
  for (StateId key : k.keys.Motion()) window->SetStateConstant(key, true);
  for (int j = 0; j < num_imus(); ++j) {
    window->AddResidualBlock(MakeInitialBiasPrior(config_), nullptr, {k.keys.Bias(j)});
  }
  window_ = window;
  if (time_offsets()) {
    const CalibrationOptions& cal = config_.calibration;
    for (int j = 0; j < num_imus(); ++j) {
      // Samples stamped up to t_0 − δ_j measure the state before the first knot.
      last_stamp_.push_back(scan.t_end - cal.TimeOffset(j));
      if (!cal.estimate_time_offset) continue;
      // δ_j: a static 1-D state with its prior, added once (calibration_blocks.h).
      AddTimeOffsetState(cal, j, window);
    }
  }
}

void GpKnotEstimator::AddState(const PreparedScan& scan, SlidingWindow* window,
                               ScanResult* result) {
  // K knots over the sweep: at t_prev + (i/K)·Δt, the last exactly at the scan end.
  imu_blocks_.clear();
  // The oldest knot, solved at least once: kept for the mean twist of an IMU outage (MeanTwist).
  const Knot& held = knots_.front();
  if (config_.gap_prediction_span > 0.0 && (history_.empty() || history_.back().t < held.t)) {
    history_.push_back(ValueOf(held));
    while (history_.size() > 1 && history_[1].t <= held.t - config_.gap_prediction_span) {
      history_.pop_front();
    }
  }
  UpdateAccelLoss(*window, result);
  const double t_prev = knots_.back().t;
  const int K = KnotsForScan(t_prev, scan.t_end);
  split_sweep_ = K > config_.knots_per_scan;
  // The sweep's own keypoint budget when it has one (a split sweep, or a slow one:
  // sweep_keypoint_budget.h), judged on the newest knot's solved speed at the sweep's start;
  // chosen from the same preprocessed points with the front end's rule, so only the cap differs.
  const double speed = Eigen::Map<const Vec6>(knots_.back().velocity).head<3>().norm();
  const int cap =
      SweepKeypointCap(config_.adaptive_knots, config_.slow_sweep_keypoints, split_sweep_, speed);
  use_own_keypoints_ = cap > 0;
  if (use_own_keypoints_) {
    own_keypoints_ = KeypointsOf(scan.points, config_.frontend.keypoint_voxel_size, cap);
  }
  for (int i = 1; i <= K; ++i) {
    const double t = i == K ? scan.t_end : t_prev + (scan.t_end - t_prev) * i / K;
    AddKnotAndFactors(t, window, result);
  }
  scan_knots_ = K;
}

void GpKnotEstimator::UpdateAccelLoss(const SlidingWindow& window, ScanResult* result) {
  if (!accel_loss_.enabled()) return;
  for (int j = 0; j < num_imus(); ++j) {
    if (!accel_loss_.Watching(j)) continue;
    // The newest knot's bias given everything so far: after the slide the window holds that knot
    // and the marginal prior, so this linearises little more than the prior (an inverse of the
    // knot's 18 + 6 per IMU dimensions, and only until the loss is relaxed).
    const Eigen::MatrixXd P = window.Covariance({knots_.back().keys.Bias(j)});
    accel_loss_.Observe(j, P.topLeftCorner<3, 3>());  // [b_a; b_g]
  }
  result->accel_loss_relaxed = accel_loss_.relaxed(0);
  result->accel_bias_sigma = accel_loss_.relaxed(0) ? 0.0 : accel_loss_.last_sigma(0);
}

int GpKnotEstimator::KnotsForScan(double t_prev, double t_end) const {
  const int fixed = config_.knots_per_scan;
  if (!uses_imu() || !config_.adaptive_knots.enabled(fixed)) return fixed;
  // The first IMU's samples of the sweep, by their stamps: a clock offset of a few ms shifts the
  // window the motion is judged on, not the judgement (knot_spacing.h).
  const std::vector<ImuSample> samples = imu_.Samples(t_prev, t_end, 0);
  std::vector<double> t;
  std::vector<Vec3> gyro, accel;
  for (const ImuSample& s : samples) {
    t.push_back(imu_.Seconds(s.t_ns) - t_prev);
    gyro.push_back(s.gyro);
    accel.push_back(s.accel);
  }
  return KnotsForSweep(config_.adaptive_knots, fixed, t, gyro, accel);
}

void GpKnotEstimator::AddKnotAndFactors(double t, SlidingWindow* window, ScanResult* result) {
  const Knot prev = knots_.back();
  const double dt = t - prev.t;
  std::vector<std::vector<ImuSample>> imu(num_imus());
  for (int j = 0; j < num_imus(); ++j) {
    if (time_offsets()) {
      // The samples whose t + δ̄_j falls into (t_prev, t], following on from the stamps
      // already taken (δ̄_j moves between scans; no sample twice, none skipped).
      const double until = std::max(last_stamp_[j], t - TimeOffset(j, *window));
      imu[j] = imu_.Samples(last_stamp_[j], until, j);
      last_stamp_[j] = until;
    } else {
      imu[j] = imu_.Samples(prev.t, t, j);
    }
  }

  std::vector<Vec6> bias;
  for (const double* b : prev.bias) bias.push_back(Eigen::Map<const Vec6>(b));
  const gp::KnotState guess = InitialGuess(prev, t, imu, *window);
  knots_.push_back(AddKnot(t, guess.pose, guess.velocity, guess.acceleration, bias, window));
  const Knot& k = knots_.back();

  // GP prior between the knots (SPEC §2).
  window->AddResidualBlock(new gp::SingerPrior(model_, dt), nullptr, KnotPair(prev.keys, k.keys));
  for (int j = 0; j < num_imus(); ++j) {
    window->AddResidualBlock(MakeBiasRandomWalk(config_, dt), nullptr,
                             {prev.keys.Bias(j), k.keys.Bias(j)});
    AddImuMeasurements(prev, k, j, imu[j], window, result);
  }
}

gp::KnotState GpKnotEstimator::InitialGuess(const Knot& prev, double t,
                                            const std::vector<std::vector<ImuSample>>& imu,
                                            const SlidingWindow& window) const {
  gp::KnotState x = gp::ReadKnotState(prev.pose, prev.velocity, prev.acceleration);
  const double dt = t - prev.t;
  // The first IMU that has samples in the interval.
  int j = 0;
  while (j < num_imus() && imu[j].empty()) ++j;
  if (j == num_imus()) {
    // No IMU sample (an outage): the mean twist of the recent estimate, else constant body
    // velocity; ϖ̇ = 0 (odometry_config.h, gap_prediction_span).
    const std::optional<Vec6> mean = MeanTwist(prev);
    const Vec6 w = mean ? *mean : x.velocity;
    return {SE3::Exp(dt * w) * x.pose, w, Vec6::Zero()};
  }
  const Vec6 bias = Eigen::Map<const Vec6>(prev.bias[j]);
  if (!config_.imu_prediction) {
    // Constant body velocity from the previous knot, the angular part from the newest gyro
    // sample (ϖ_φ = −C_ri(ω_meas − b_g), SPEC §1, imu_mounting.h).
    Vec6 w = x.velocity;
    w.tail<3>() = -(mountings_[j].C_ri * (imu[j].back().gyro - bias.tail<3>()));
    return {SE3::Exp(dt * w) * x.pose, w, Vec6::Zero()};
  }
  // The samples integrated from the previous knot (imu_knot_prediction.h), at the times they
  // measure (t + δ_j).
  const double delta = time_offsets() ? TimeOffset(j, window) : 0.0;
  std::vector<TimedImuSample> samples;
  samples.reserve(imu[j].size());
  for (const ImuSample& s : imu[j]) {
    samples.push_back({imu_.Seconds(s.t_ns) + delta, s.gyro, s.accel});
  }
  ImuPredictionModel model;
  model.mounting = mountings_[j];
  model.gravity = config_.gravity;
  model.accel_model = config_.exact_specific_force ? imu::AccelModel::kSpecificForce
                                                   : imu::AccelModel::kBodyCentric;
  model.has_accelerometer = config_.method == LioMethod::kSingerLio;
  const Mat3 C_mi = model.has_accelerometer ? RotationManifold::Rotation(window.State(kGravityKey))
                                            : Mat3::Identity();
  return PredictKnotWithImu(x, prev.t, t, samples, bias, C_mi, model);
}

std::unique_ptr<LidarTerm> GpKnotEstimator::MakeLidarTerm(const PreparedScan& scan,
                                                          SlidingWindow* window) const {
  // The knots from the previous scan's end to this one's.
  std::vector<TimedKnot> knots;
  for (size_t i = ScanStartIndex(); i < knots_.size(); ++i) {
    knots.push_back({knots_[i].t, knots_[i].keys});
  }
  const std::vector<TimedPoint>& keypoints = use_own_keypoints_ ? own_keypoints_ : scan.keypoints;
  auto term = estimates_extrinsic()
                  ? std::make_unique<ContinuousLidarTerm>(model_, knots, keypoints,
                                                          scan.T_robot_lidar, window)
                  : std::make_unique<ContinuousLidarTerm>(model_, knots, keypoints, window);
  term->set_residual_blocks(config_.frontend.residual_blocks);
  return term;
}

void GpKnotEstimator::MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const {
  const Knot& prev = ScanStart();
  const Knot& k = knots_.back();
  // The GP pose on a 1 ms grid over the sweep's intervals, and between grid nodes the constant
  // twist of the node pair (geodesic interpolation): the deviation from the GP mean is
  // ~½·|ω̇|·(0.5 ms)², 1.3e-5 rad at 100 rad/s² (0.6 mm at 50 m), while the 1 800 firings of a
  // sweep no longer each need their own GP interpolator.
  const int nodes = std::max(2, static_cast<int>(std::ceil((k.t - prev.t) / 1e-3)) + 1);
  const double step = (k.t - prev.t) / (nodes - 1);
  std::vector<SE3> grid(nodes);
  std::vector<Vec6> twist(nodes - 1);
  for (int j = 0; j < nodes; ++j) grid[j] = PoseSinceScanStart(prev.t + j * step);
  for (int j = 0; j + 1 < nodes; ++j) twist[j] = (grid[j + 1] * grid[j].Inverse()).Log();
  // With calibration, the points were moved into the robot frame with the extrinsic of the
  // preparation; they enter the map with the current estimate: T_mr(τ)·T_rl·T_prep⁻¹·q.
  const bool recalibrate = extrinsic_ != nullptr;
  const SE3 correction =
      recalibrate ? PoseManifold::Pose(extrinsic_) * scan.T_robot_lidar.Inverse() : SE3();
  out->clear();
  out->reserve(scan.points.size());
  double last_tau = -1.0;
  SE3 T_mr_tau;
  for (const TimedPoint& p : scan.points) {
    if (p.time != last_tau) {  // points of one firing share the pose
      const double u = std::clamp((p.time - prev.t) / step, 0.0, nodes - 1.0);
      const int j = std::min(static_cast<int>(u), nodes - 2);
      T_mr_tau = SE3::Exp((u - j) * twist[j]) * grid[j];
      if (recalibrate) T_mr_tau = T_mr_tau * correction;
      last_tau = p.time;
    }
    out->push_back(T_mr_tau * p.point);
  }
}

}  // namespace ctlio::lio
