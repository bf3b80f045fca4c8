#include "ctlio/solvers/lio/nav_state_estimator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ctlio/factors/gp/vector_prior.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/factors/lidar/point_to_plane_world.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/bias_priors.h"
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
// previous state's current estimate (re-integrated every round), at the single pose T_wb.
class DeskewedLidarTerm final : public LidarTerm {
 public:
  DeskewedLidarTerm(const NavStateEstimator& estimator, const NavStateEstimator::State& prev,
                    const NavStateEstimator::State& s, const std::vector<TimedPoint>& keypoints)
      : estimator_(estimator), prev_(prev), s_(s), keypoints_(keypoints) {}

  size_t num_keypoints() const override { return keypoints_.size(); }
  void BeginRound() override {
    table_ = estimator_.Deskew(prev_, s_);
    T_wb_ = PoseManifold::Pose(s_.pose);
  }
  void Locate(size_t i, Vec3* q, Vec3* p_map) override {
    *q = table_.ToEnd(keypoints_[i].time, keypoints_[i].point);
    *p_map = T_wb_ * *q;
  }
  ceres::ResidualBlockId AddResidual(size_t i, const PlaneAssociation& association,
                                     ceres::LossFunction* loss, SlidingWindow* window) override {
    if (costs_.empty()) costs_.resize(keypoints_.size(), nullptr);
    costs_[i] = new PointToPlaneWorld(association);
    return window->AddResidualBlock(costs_[i], loss, {s_.keys.pose});
  }
  void UpdateResidual(size_t i, const PlaneAssociation& association) override {
    costs_[i]->set_association(association);
  }
  SE3 NewestPose() const override { return PoseManifold::Pose(s_.pose); }

 private:
  const NavStateEstimator& estimator_;
  NavStateEstimator::State prev_, s_;
  const std::vector<TimedPoint>& keypoints_;
  NavStateEstimator::DeskewTable table_;
  SE3 T_wb_;
  // Per keypoint: its residual's cost function (owned by the window), for UpdateResidual.
  std::vector<PointToPlaneWorld*> costs_;
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

NavStateEstimator::NavStateEstimator(const OdometryConfig& config, const ImuBuffer& imu)
    : config_(config), imu_(imu) {}

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
  InterpolateAtMidpoints(imu_, imu_.samples(config_.input_imu), &segments);
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
  table.t.push_back(from.t);
  table.T_wb.push_back(PoseManifold::Pose(from.pose));
  for (const ImuSegment& seg : InputSegments(from.t, t_end, nullptr)) {
    pim.Integrate(seg.accel, seg.gyro, seg.dt);
    const imu::NavState x = pim.Predict(start, bias, gravity_map_);
    table.t.push_back(seg.t_begin + seg.dt);
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
}

void NavStateEstimator::Initialise(const PreparedScan& scan, const Mat3& C_mi,
                                   SlidingWindow* window) {
  // The platform is still at start (gravity initialisation checked it): the first state is the
  // map origin at rest, held constant (which fixes the gauge); its biases are free under the
  // initial bias prior, as in Singer-LIO.
  gravity_map_ = C_mi * Vec3(0, 0, -config_.gravity);
  states_.push_back(AddNavState(scan.t_end, SE3(), Vec3::Zero(), Vec6::Zero(), window));
  const State& s = states_.back();
  window->SetStateConstant(s.keys.pose, true);
  window->SetStateConstant(s.keys.velocity, true);
  window->AddResidualBlock(MakeInitialBiasPrior(config_), nullptr, {s.keys.bias});
}

void NavStateEstimator::AddState(const PreparedScan& scan, SlidingWindow* window,
                                 ScanResult* result) {
  const State prev = states_.back();
  double max_gap = 0.0;
  const std::vector<ImuSegment> segments = InputSegments(prev.t, scan.t_end, &max_gap);
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
  window->AddResidualBlock(
      new imu::PreintegratedImuFactor(pim, gravity_map_), nullptr,
      {prev.keys.pose, prev.keys.velocity, prev.keys.bias, s.keys.pose, s.keys.velocity});
  window->AddResidualBlock(MakeBiasRandomWalk(config_, s.t - prev.t), nullptr,
                           {prev.keys.bias, s.keys.bias});
  result->imu_residuals = 1;
}

std::unique_ptr<LidarTerm> NavStateEstimator::MakeLidarTerm(const PreparedScan& scan,
                                                            SlidingWindow*) const {
  return std::make_unique<DeskewedLidarTerm>(*this, states_[states_.size() - 2], states_.back(),
                                             scan.keypoints);
}

void NavStateEstimator::MapPoints(const PreparedScan& scan, std::vector<Vec3>* out) const {
  const State& s = states_.back();
  const DeskewTable table = Deskew(states_[states_.size() - 2], s);
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  out->clear();
  out->reserve(scan.points.size());
  for (const TimedPoint& p : scan.points) out->push_back(T_wb * table.ToEnd(p.time, p.point));
}

}  // namespace ctlio::lio
