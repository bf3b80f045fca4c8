#include "ctlio/solvers/lio/nav_state_estimator.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/factors/gp/vector_prior.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/factors/imu/preintegrated_imu_time_offset_factor.h"
#include "ctlio/factors/lidar/point_to_plane_world.h"
#include "ctlio/factors/lidar/point_to_plane_world_calibrated.h"
#include "ctlio/factors/lidar/point_to_plane_world_calibrated_batch.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/bias_priors.h"
#include "ctlio/solvers/lio/calibration_blocks.h"
#include "ctlio/solvers/lio/imu_midpoint.h"

namespace ctlio::lio {

namespace {

// Continuous noise densities σ/√rate of the per-sample standard deviations (SPEC §6).
imu::ImuNoise InputNoise(const OdometryConfig& config) {
  imu::ImuNoise noise;
  noise.gyro_noise_density = config.input_gyro_sigma / std::sqrt(config.imu_rate_hint);
  noise.accel_noise_density = config.input_accel_sigma / std::sqrt(config.imu_rate_hint);
  return noise;
}

imu::NavState ReadNavState(const NavStateEstimator::State& s) {
  imu::NavState x;
  const SE3 T = PoseManifold::Pose(s.pose);
  x.C = T.rotation();
  x.p = T.translation();
  x.v = Eigen::Map<const Vec3>(s.velocity);
  return x;
}

// The keypoints deskewed into the body frame at the scan end by the IMU integrated from the
// previous state's current estimate (re-integrated every round, at the current clock offset), at
// the single pose T_wb. With online calibration each keypoint enters from the lidar frame through
// T_rl and the deskew moves with the clock offset to first order (PointToPlaneWorldCalibrated's
// per-point twist ξ = Ad(D)·ν(τ) − ν(t_end)), the
// scan's keypoints batched into one block unless lidar_frontend.residual_blocks is "point"
// (PointToPlaneWorldCalibratedBatch: ~600 per-keypoint blocks with the calibration states were
// 93 ms per scan on medium/0, docs/experiments/calibration.md). Without calibration the
// per-keypoint blocks stay (the baseline's results as before).
class DeskewedLidarTerm final : public LidarTerm {
 public:
  DeskewedLidarTerm(const NavStateEstimator& estimator, const NavStateEstimator::State& prev,
                    const NavStateEstimator::State& s, const PreparedScan& scan)
      : estimator_(estimator),
        prev_(prev),
        s_(s),
        keypoints_(scan.keypoints),
        calibrated_(estimator.config().calibration.any()),
        batched_(calibrated_ && estimator.config().frontend.residual_blocks != "point"),
        square_root_(estimator.config().frontend.residual_blocks == "square_root"),
        offset_(estimator.estimates_time_offset()) {
    if (!calibrated_) return;
    // The lidar-frame points (prepared with the extrinsic estimate of the scan's start).
    const SE3 T_lidar_robot = scan.T_robot_lidar.Inverse();
    q_l_.reserve(keypoints_.size());
    for (const TimedPoint& k : keypoints_) q_l_.push_back(T_lidar_robot * k.point);
    deskew_.resize(keypoints_.size());
    twist_.resize(keypoints_.size(), Vec6::Zero());
  }

  size_t num_keypoints() const override { return keypoints_.size(); }
  void BeginRound() override {
    table_ = estimator_.Deskew(prev_, s_);
    T_wb_ = PoseManifold::Pose(s_.pose);
    if (!calibrated_) return;
    T_rl_ = estimator_.Extrinsic();
    anchor_ = estimator_.TimeOffset();  // the table's offset
    end_twist_ = table_.TwistAt(table_.t.empty() ? 0.0 : table_.t.back());
  }
  void Locate(size_t i, Vec3* q, Vec3* p_map) override {
    if (calibrated_) {
      deskew_[i] = table_.T_end_inv * table_.Interpolate(keypoints_[i].time);
      if (offset_) {
        twist_[i] = deskew_[i].Adjoint() * table_.TwistAt(keypoints_[i].time) - end_twist_;
      }
      *q = deskew_[i] * (T_rl_ * q_l_[i]);
    } else {
      *q = table_.ToEnd(keypoints_[i].time, keypoints_[i].point);
    }
    *p_map = T_wb_ * *q;
  }
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& association,
                                     ceres::LossFunction* loss, SlidingWindow* window) override {
    if (calibrated_) {
      if (calibrated_costs_.empty()) calibrated_costs_.resize(keypoints_.size(), nullptr);
      const bool extrinsic = estimator_.estimates_extrinsic();
      calibrated_costs_[i] = new PointToPlaneWorldCalibrated(association, q_l_[i], Geometry(i),
                                                             extrinsic, offset_, T_rl_);
      std::vector<StateId> blocks = {s_.keys.pose};
      if (extrinsic) blocks.push_back(kExtrinsicKey);
      if (offset_) blocks.push_back(TimeOffsetKey(estimator_.config().input_imu));
      return window->AddResidualBlock(calibrated_costs_[i], loss, blocks);
    }
    if (costs_.empty()) costs_.resize(keypoints_.size(), nullptr);
    costs_[i] = new PointToPlaneWorld(association);
    return window->AddResidualBlock(costs_[i], loss, {s_.keys.pose});
  }
  void UpdateResidual(size_t i, const PlaneAssociation& association) override {
    if (calibrated_) {
      calibrated_costs_[i]->Update(association, Geometry(i));
    } else {
      costs_[i]->set_association(association);
    }
  }
  SE3 NewestPose() const override { return PoseManifold::Pose(s_.pose); }

  bool batched() const override { return batched_; }
  void SetBatchResiduals(const std::vector<uint8_t>& associated,
                         const std::vector<PlaneAssociation>& planes,
                         const std::shared_ptr<const ceres::LossFunction>& loss,
                         SlidingWindow* window,
                         std::vector<ceres::ResidualBlockId>* blocks) override {
    for (ceres::ResidualBlockId id : *blocks) window->RemoveResidualBlock(id);
    blocks->clear();
    std::vector<PointToPlaneWorldCalibratedBatch::Point> points;
    for (size_t i = 0; i < keypoints_.size(); ++i) {
      if (associated[i]) points.push_back({planes[i], q_l_[i], deskew_[i], twist_[i]});
    }
    if (points.empty()) return;
    const bool extrinsic = estimator_.estimates_extrinsic();
    using Form = PointToPlaneWorldCalibratedBatch::Form;
    // W + 1 ≤ 14 rows: the square-root form only for more points than that.
    const int w = 6 + (extrinsic ? 6 : 0) + (offset_ ? 1 : 0);
    const Form form = square_root_ && static_cast<int>(points.size()) > w + 1 ? Form::kSquareRoot
                                                                              : Form::kPointRows;
    auto* batch = new PointToPlaneWorldCalibratedBatch(std::move(points), anchor_, loss, extrinsic,
                                                       offset_, T_rl_, form);
    std::vector<StateId> states = {s_.keys.pose};
    if (extrinsic) states.push_back(kExtrinsicKey);
    if (offset_) states.push_back(TimeOffsetKey(estimator_.config().input_imu));
    blocks->push_back(window->AddResidualBlock(batch, nullptr, states));
  }

 private:
  PointToPlaneWorldCalibrated::Geometry Geometry(size_t i) const {
    PointToPlaneWorldCalibrated::Geometry g;
    g.deskew = deskew_[i];
    g.twist = twist_[i];
    g.offset_anchor = anchor_;
    return g;
  }

  const NavStateEstimator& estimator_;
  NavStateEstimator::State prev_, s_;
  const std::vector<TimedPoint>& keypoints_;
  NavStateEstimator::DeskewTable table_;
  SE3 T_wb_;
  // Per keypoint: its residual's cost function (owned by the window), for UpdateResidual.
  std::vector<PointToPlaneWorld*> costs_;
  // Online calibration: the lidar-frame points, this round's T_rl, offset δ̄ of the deskew, and
  // per point the deskew and its twist with the offset.
  const bool calibrated_, batched_, square_root_, offset_;
  std::vector<Vec3> q_l_;
  std::vector<SE3> deskew_;
  std::vector<Vec6> twist_;
  SE3 T_rl_;
  double anchor_ = 0.0;
  Vec6 end_twist_ = Vec6::Zero();
  std::vector<PointToPlaneWorldCalibrated*> calibrated_costs_;
};

}  // namespace

SE3 NavStateEstimator::DeskewTable::Interpolate(double tau) const {
  if (t.empty()) return SE3();
  if (tau <= t.front()) return T_wb.front();
  if (tau >= t.back()) return T_wb.back();
  const size_t j = std::upper_bound(t.begin(), t.end(), tau) - t.begin();
  const size_t i = j - 1;
  const double s = (tau - t[i]) / std::max(t[j] - t[i], 1e-12);
  // Within one IMU period the motion is a constant twist: interpolate on the group.
  const Vec6 xi = (T_wb[j] * T_wb[i].Inverse()).Log();
  return SE3::Exp(s * xi) * T_wb[i];
}

Vec6 NavStateEstimator::DeskewTable::TwistAt(double tau) const {
  const size_t n = t.size();
  if (n < 2) return Vec6::Zero();
  // The segment [t_k, t_k+1] holding τ (the first or last one outside the table).
  const size_t j =
      std::clamp<size_t>(std::upper_bound(t.begin(), t.end(), tau) - t.begin(), 1, n - 1);
  const double dt = std::max(t[j] - t[j - 1], 1e-12);
  return (T_wb[j - 1].Inverse() * T_wb[j]).Log() / dt;
}

NavStateEstimator::NavStateEstimator(const OdometryConfig& config, const ImuBuffer& imu)
    : config_(config), imu_(imu) {
  if (config_.calibration.estimate_time_offset && config_.num_imus() > 1) {
    throw std::invalid_argument(
        "calibration.estimate_time_offset: the IMU-as-input baseline estimates the clock offset "
        "of one IMU; this config has " +
        std::to_string(config_.num_imus()));
  }
}

SE3 NavStateEstimator::Extrinsic() const {
  return estimates_extrinsic() && window_ != nullptr ? window_->Pose(kExtrinsicKey)
                                                     : config_.T_imu_lidar;
}

double NavStateEstimator::TimeOffset() const {
  return estimates_time_offset() && window_ != nullptr
             ? window_->State(TimeOffsetKey(config_.input_imu))[0]
             : config_.calibration.TimeOffset(config_.input_imu);
}

NavStateEstimator::State NavStateEstimator::AddNavState(double t, const SE3& T_wb, const Vec3& v,
                                                        const Vec6& bias, SlidingWindow* window) {
  State s;
  s.t = t;
  s.keys = NavStateKeys::ForState(next_state_++);
  s.pose = window->AddPoseState(s.keys.pose, T_wb);
  s.velocity = window->AddVectorState(s.keys.velocity, v);
  s.bias = window->AddVectorState(s.keys.bias, bias);
  return s;
}

std::vector<ImuSegment> NavStateEstimator::InputSegments(double t_a, double t_b,
                                                         double* max_gap) const {
  std::vector<ImuSegment> segments = imu_.Segments(t_a, t_b, max_gap, config_.input_imu);
  if (config_.input_midpoint) {
    SplitSegments(config_.input_substeps, &segments);
    if (config_.input_interpolation == "cubic") {
      InterpolateCubicAtMidpoints(imu_, imu_.samples(config_.input_imu), &segments);
    } else {
      InterpolateAtMidpoints(imu_, imu_.samples(config_.input_imu), &segments);
    }
  }
  const Mat3 C_ri = config_.ImuPose(config_.input_imu).rotation();
  if (!C_ri.isIdentity(0.0)) {
    for (ImuSegment& seg : segments) {
      seg.gyro = C_ri * seg.gyro;
      seg.accel = C_ri * seg.accel;
    }
  }
  return segments;
}

NavStateEstimator::DeskewTable NavStateEstimator::Integrate(const State& from, double t_end) const {
  DeskewTable table;
  const Vec6 bias = Eigen::Map<const Vec6>(from.bias);
  imu::PreintegratedImu pim(bias, InputNoise(config_));
  const imu::NavState start = ReadNavState(from);
  // On the IMU clock over [from.t − δ, t_end − δ], listed on the lidar clock (+δ).
  const double offset = TimeOffset();
  table.t.push_back(from.t);
  table.T_wb.push_back(PoseManifold::Pose(from.pose));
  for (const ImuSegment& seg : InputSegments(from.t - offset, t_end - offset, nullptr)) {
    pim.Integrate(seg.accel, seg.gyro, seg.dt);
    const imu::NavState x = pim.Predict(start, bias, gravity_map_);
    table.t.push_back(seg.t_begin + seg.dt + offset);
    table.T_wb.push_back(SE3(x.C, x.p));
  }
  table.T_end_inv = table.T_wb.back().Inverse();
  return table;
}

NavStateEstimator::DeskewTable NavStateEstimator::Deskew(const State& from, const State& to) const {
  if (!to.after_gap) return Integrate(from, to.t);
  DeskewTable table;
  table.t = {from.t, to.t};
  table.T_wb = {PoseManifold::Pose(from.pose), PoseManifold::Pose(to.pose)};
  table.T_end_inv = table.T_wb.back().Inverse();
  return table;
}

std::string NavStateEstimator::ImuGapRecovery() const {
  if (config_.gap_zero_order_hold) return "bridged by holding the last sample";
  return "held over holes up to imu.gap_hold_max; longer ones not preintegrated: constant-twist "
         "prediction, lidar-only registration, velocity random "
         "walk; the preintegration restarts from the estimate when the IMU returns";
}

void NavStateEstimator::AddStateAcrossGap(const State& prev, double t_end, SlidingWindow* window) {
  const double dt = t_end - prev.t;
  const SE3 T_prev = PoseManifold::Pose(prev.pose);
  SE3 T_pred = T_prev;
  Vec3 v = Eigen::Map<const Vec3>(prev.velocity);
  if (states_.size() >= 2) {
    // Constant body twist of the last interval, extrapolated (SE(3) constant velocity).
    const State& before = states_[states_.size() - 2];
    const Vec6 xi = (PoseManifold::Pose(before.pose).Inverse() * T_prev).Log();
    T_pred = T_prev * SE3::Exp(xi * (dt / std::max(prev.t - before.t, 1e-6)));
  } else {
    T_pred = SE3(T_prev.rotation(), T_prev.translation() + dt * v);
  }
  const Vec6 bias = Eigen::Map<const Vec6>(prev.bias);
  states_.push_back(AddNavState(t_end, T_pred, v, bias, window));
  State& s = states_.back();
  s.after_gap = true;
  // v_s − v_prev ~ N(0, q·Δt·I): VectorGpPrior with Φ = I (a random walk on the velocity).
  const Mat3 sqrt_info = Mat3::Identity() / std::sqrt(config_.gap_velocity_walk * dt);
  window->AddResidualBlock(new gp::VectorGpPrior<3>(Mat3::Identity(), sqrt_info), nullptr,
                           {prev.keys.velocity, s.keys.velocity});
  window->AddResidualBlock(MakeBiasRandomWalk(config_, dt), nullptr, {prev.keys.bias, s.keys.bias});
}

SE3 NavStateEstimator::NewestPose() const { return PoseManifold::Pose(states_.back().pose); }

std::vector<SE3> NavStateEstimator::PosesSincePrevious(const std::vector<double>& t) const {
  const State& s = states_.back();
  const DeskewTable table = Integrate(states_[states_.size() - 2], s.t);
  const SE3 T_wb_end = PoseManifold::Pose(s.pose) * table.T_end_inv;
  std::vector<SE3> poses;
  poses.reserve(t.size());
  for (const double tau : t) poses.push_back(T_wb_end * table.Interpolate(tau));
  return poses;
}

SE3 NavStateEstimator::AnchoredPose(const DeskewTable& from_a, double t_b, const SE3& T_b,
                                    double tau) {
  // The IMU propagated from the final state a (its pose, velocity and bias) never ends exactly at
  // the final state b: the preintegration factor is one soft constraint among the window's. Held
  // at one end only, the trajectory jumps at the other (the live trajectory's jump at every scan:
  // 6.9 mm median on the main job). The mismatch E = T_b·P(t_b)⁻¹ is spread over the segment
  // linearly in its tangent, Exp(s·Log E)·P(τ) with s = (τ − t_a)/(t_b − t_a): both ends are the
  // final values, and in between the correction is a constant twist added to the propagation
  // (the mismatch comes from the final velocity and bias, whose errors grow smoothly from a).
  const double t_a = from_a.t.front();
  const double s = std::clamp((tau - t_a) / std::max(t_b - t_a, 1e-12), 0.0, 1.0);
  const Vec6 mismatch = (T_b * from_a.T_end_inv).Log();
  return SE3::Exp(s * mismatch) * from_a.Interpolate(tau);
}

std::vector<double> NavStateEstimator::StateTimes() const {
  std::vector<double> t;
  for (const State& s : states_) t.push_back(s.t);
  return t;
}

std::vector<SE3> NavStateEstimator::SealOldest(const std::vector<double>& t) {
  const State& k = states_.front();
  const SE3 T_k = PoseManifold::Pose(k.pose);
  std::vector<SE3> poses;
  poses.reserve(t.size());
  for (const double tau : t) {
    poses.push_back(tau >= k.t || !sealed_ ? T_k : AnchoredPose(*sealed_, k.t, T_k, tau));
  }
  // Propagated now, from k's final value, while the IMU buffer still holds the interval (it is
  // trimmed behind the newest scan).
  sealed_.reset();
  if (states_.size() >= 2) sealed_ = Deskew(k, states_[1]);
  return poses;
}

std::vector<SE3> NavStateEstimator::UnsealedPoses(const std::vector<double>& t) const {
  std::vector<SE3> poses;
  poses.reserve(t.size());
  size_t i = 0;  // the first state at or after τ (or the last)
  size_t table_for = 0;
  DeskewTable table;  // the segment ending at states_[table_for] (from sealed_ for 0)
  for (const double tau : t) {
    while (i + 1 < states_.size() && states_[i].t < tau) ++i;
    const SE3 T_i = PoseManifold::Pose(states_[i].pose);
    if (tau >= states_[i].t || (i == 0 && !sealed_)) {
      poses.push_back(T_i);
      continue;
    }
    if (table_for != i || table.t.empty()) {
      table = i == 0 ? *sealed_ : Deskew(states_[i - 1], states_[i]);
      table_for = i;
    }
    poses.push_back(AnchoredPose(table, states_[i].t, T_i, tau));
  }
  return poses;
}

SE3 NavStateEstimator::PreviousPose() const {
  return PoseManifold::Pose(states_[states_.size() - 2].pose);
}

void NavStateEstimator::Report(ScanResult* result) const {
  const State& s = states_.back();
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  result->T_mr = T_wb;
  result->velocity.head<3>() = T_wb.rotation().transpose() * Eigen::Map<const Vec3>(s.velocity);
  result->velocity.tail<3>().setZero();
  result->bias = Eigen::Map<const Vec6>(s.bias);
  if (estimates_time_offset()) result->calibration.time_offset_s = {TimeOffset()};
  if (estimates_extrinsic()) {
    result->calibration.has_extrinsic = true;
    result->calibration.T_imu_lidar = Extrinsic();
  }
}

void NavStateEstimator::Initialise(const PreparedScan& scan, const Mat3& C_mi,
                                   SlidingWindow* window) {
  // The platform is still at start (gravity initialisation checked it): the first state is the
  // map origin at rest, held constant (which fixes the gauge); its biases are free under the
  // initial bias prior, as in Singer-LIO.
  gravity_map_ = C_mi * Vec3(0, 0, -config_.gravity);
  // The calibration states and their priors, as Singer-LIO's (calibration_blocks.h).
  window_ = window;
  if (estimates_extrinsic()) AddExtrinsicState(config_, window);
  if (estimates_time_offset()) AddTimeOffsetState(config_.calibration, config_.input_imu, window);
  states_.push_back(AddNavState(scan.t_end, SE3(), Vec3::Zero(), Vec6::Zero(), window));
  const State& s = states_.back();
  window->SetStateConstant(s.keys.pose, true);
  window->SetStateConstant(s.keys.velocity, true);
  window->AddResidualBlock(MakeInitialBiasPrior(config_), nullptr, {s.keys.bias});
}

void NavStateEstimator::AddState(const PreparedScan& scan, SlidingWindow* window,
                                 ScanResult* result) {
  imu_blocks_.clear();
  const State prev = states_.back();
  double max_gap = 0.0;
  // On the IMU clock: from the previous state to this scan's end at the current offset estimate
  // δ̄, the anchor of the interval's first-order shift with δ
  // (preintegrated_imu_time_offset_factor.h).
  const double offset = TimeOffset();
  const std::vector<ImuSegment> segments =
      InputSegments(prev.t - offset, scan.t_end - offset, &max_gap);
  if (!config_.gap_zero_order_hold && (segments.empty() || max_gap > config_.gap_hold_max)) {
    AddStateAcrossGap(prev, scan.t_end, window);
    result->imu_residuals = 0;
    return;
  }
  if (segments.empty()) throw std::runtime_error("no IMU samples for this scan");

  // Preintegration between the two states, linearised at the previous bias estimate; its
  // prediction is the initial guess.
  const Vec6 bias_hat = Eigen::Map<const Vec6>(prev.bias);
  imu::PreintegratedImu pim(bias_hat, InputNoise(config_));
  for (const ImuSegment& seg : segments) pim.Integrate(seg.accel, seg.gyro, seg.dt);
  const imu::NavState pred = pim.Predict(ReadNavState(prev), bias_hat, gravity_map_);
  states_.push_back(AddNavState(scan.t_end, SE3(pred.C, pred.p), pred.v, bias_hat, window));
  const State& s = states_.back();
  std::vector<StateId> blocks = {prev.keys.pose, prev.keys.velocity, prev.keys.bias, s.keys.pose,
                                 s.keys.velocity};
  ceres::CostFunction* factor = nullptr;
  if (estimates_time_offset()) {
    imu::PreintegrationEnds ends;
    ends.accel_begin = segments.front().accel;
    ends.gyro_begin = segments.front().gyro;
    ends.accel_end = segments.back().accel;
    ends.gyro_end = segments.back().gyro;
    factor = new imu::PreintegratedImuTimeOffsetFactor(pim, gravity_map_, ends, offset);
    blocks.push_back(TimeOffsetKey(config_.input_imu));
  } else {
    factor = new imu::PreintegratedImuFactor(pim, gravity_map_);
  }
  imu_blocks_.accel.push_back(window->AddResidualBlock(factor, nullptr, blocks));
  window->AddResidualBlock(MakeBiasRandomWalk(config_, s.t - prev.t), nullptr,
                           {prev.keys.bias, s.keys.bias});
  result->imu_residuals = 1;
}

std::unique_ptr<LidarTerm> NavStateEstimator::MakeLidarTerm(const PreparedScan& scan,
                                                            SlidingWindow*) const {
  return std::make_unique<DeskewedLidarTerm>(*this, states_[states_.size() - 2], states_.back(),
                                             scan);
}

void NavStateEstimator::MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const {
  const State& s = states_.back();
  const DeskewTable table = Deskew(states_[states_.size() - 2], s);
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  out->clear();
  out->reserve(scan.points.size());
  if (config_.calibration.any()) {
    // The final extrinsic estimate: the points moved with T_rl.
    const SE3 recalibrate = Extrinsic() * scan.T_robot_lidar.Inverse();
    for (const TimedPoint& p : scan.points) {
      out->push_back(T_wb * table.ToEnd(p.time, recalibrate * p.point));
    }
    return;
  }
  for (const TimedPoint& p : scan.points) out->push_back(T_wb * table.ToEnd(p.time, p.point));
}

}  // namespace ctlio::lio
