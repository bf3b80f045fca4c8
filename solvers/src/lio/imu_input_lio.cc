#include "ctlio/solvers/lio/imu_input_lio.h"

#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/solvers/lio/lio_residuals.h"

namespace ctlio::lio {

SE3 ImuInputLio::DeskewTable::Interpolate(double tau) const {
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

ImuInputLio::ImuInputLio(const OdometryConfig& config) : LioOdometry(config) {}

ImuInputLio::~ImuInputLio() = default;

ImuInputLio::State ImuInputLio::AddState(double t, int64_t t_ns, const SE3& T_wb, const Vec3& v,
                                         const Vec6& bias) {
  State s;
  s.t = t;
  s.t_ns = t_ns;
  s.id = 8 * next_state_++;
  s.pose = window_.AddPoseState(s.id, T_wb);
  s.velocity = window_.AddVectorState(s.id + 1, v);
  s.bias = window_.AddVectorState(s.id + 3, bias);
  return s;
}

ImuInputLio::DeskewTable ImuInputLio::Integrate(const State& from, double t_end) const {
  DeskewTable table;
  const Vec6 bias = Eigen::Map<const Vec6>(from.bias);
  imu::ImuNoise noise;
  noise.gyro_noise_density = config_.input_gyro_sigma / std::sqrt(config_.imu_rate_hint);
  noise.accel_noise_density = config_.input_accel_sigma / std::sqrt(config_.imu_rate_hint);
  imu::PreintegratedImu pim(bias, noise);
  imu::NavState start;
  const SE3 T0 = PoseManifold::Pose(from.pose);
  start.C = T0.rotation();
  start.p = T0.translation();
  start.v = Eigen::Map<const Vec3>(from.velocity);
  table.t.push_back(from.t);
  table.T_wb.push_back(T0);
  double max_gap = 0.0;
  for (const ImuSegment& seg : ImuSegments(from.t, t_end, &max_gap)) {
    pim.Integrate(seg.accel, seg.gyro, seg.dt);
    const imu::NavState x = pim.Predict(start, bias, gravity_map());
    table.t.push_back(seg.t_begin + seg.dt);
    table.T_wb.push_back(SE3(x.C, x.p));
  }
  return table;
}

void ImuInputLio::Fill(const State& s, ScanStatus status, ScanResult* result) const {
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  result->T_mr = T_wb;
  result->velocity.head<3>() = T_wb.rotation().transpose() * Eigen::Map<const Vec3>(s.velocity);
  result->velocity.tail<3>().setZero();
  result->bias = Eigen::Map<const Vec6>(s.bias);
  if (result->status == ScanStatus::kOk) result->status = status;
}

void ImuInputLio::Initialise(const PreparedScan& scan, ScanResult* result) {
  // The platform is still at start (gravity initialisation checked it): the first state is the
  // map origin at rest, held constant (which fixes the gauge); its biases are free under the
  // initial bias prior, as in Singer-LIO.
  states_.push_back(AddState(scan.t_end, scan.end_ns, SE3(), Vec3::Zero(), Vec6::Zero()));
  const State& s = states_.back();
  window_.SetStateConstant(s.id, true);
  window_.SetStateConstant(s.id + 1, true);
  Vec6 variance;
  variance << Vec3::Constant(config_.initial_bias_accel_variance),
      Vec3::Constant(config_.initial_bias_gyro_variance);
  window_.AddResidualBlock(
      EuclideanPrior<6>::FromCovariance(Vec6::Zero(), variance.asDiagonal().toDenseMatrix()),
      nullptr, {s.id + 3});
  std::vector<Vec3> map_points;
  map_points.reserve(scan.points.size());
  for (const TimedPoint& p : scan.points) map_points.push_back(p.point);
  frontend_.UpdateMap(map_points, Vec3::Zero());
  Fill(s, ScanStatus::kOk, result);
}

void ImuInputLio::Process(const PreparedScan& scan, ScanResult* result) {
  Slide(result);
  const State prev = states_.back();
  const double t_s = scan.t_end;

  double max_gap = 0.0;
  const std::vector<ImuSegment> segments = ImuSegments(prev.t, t_s, &max_gap);
  if (segments.empty()) throw std::runtime_error("no IMU samples for this scan");
  if (max_gap > config_.max_imu_gap) {
    std::ostringstream m;
    m << "IMU gap of " << max_gap << " s (limit " << config_.max_imu_gap
      << " s): bridged by holding the last sample";
    result->status = ScanStatus::kImuGap;
    result->message = m.str();
  }

  // Preintegration between the two states, linearised at the previous bias estimate.
  const Vec6 bias_hat = Eigen::Map<const Vec6>(prev.bias);
  imu::ImuNoise noise;
  noise.gyro_noise_density = config_.input_gyro_sigma / std::sqrt(config_.imu_rate_hint);
  noise.accel_noise_density = config_.input_accel_sigma / std::sqrt(config_.imu_rate_hint);
  imu::PreintegratedImu pim(bias_hat, noise);
  for (const ImuSegment& seg : segments) pim.Integrate(seg.accel, seg.gyro, seg.dt);

  // Initial guess: the IMU prediction.
  imu::NavState start;
  const SE3 T_prev = PoseManifold::Pose(prev.pose);
  start.C = T_prev.rotation();
  start.p = T_prev.translation();
  start.v = Eigen::Map<const Vec3>(prev.velocity);
  const imu::NavState pred = pim.Predict(start, bias_hat, gravity_map());
  states_.push_back(AddState(t_s, scan.end_ns, SE3(pred.C, pred.p), pred.v, bias_hat));
  const State& s = states_.back();
  window_.AddResidualBlock(new imu::PreintegratedImuFactor(pim, gravity_map()), nullptr,
                           {prev.id, prev.id + 1, prev.id + 3, s.id, s.id + 1});
  window_.AddResidualBlock(MakeBiasRandomWalk(config_, s.t - prev.t), nullptr,
                           {prev.id + 3, s.id + 3});
  result->imu_residuals = 1;

  PlaneAssociator associator(frontend_.map(), config_.frontend);
  const auto add_lidar = [&](ceres::LossFunction* loss,
                             std::vector<ceres::ResidualBlockId>* blocks) {
    // Deskew with the current estimate: every point moved into the body frame at the scan end
    // by the IMU-integrated motion.
    const DeskewTable table = Integrate(prev, s.t);
    const SE3 T_end_inv = table.T_wb.back().Inverse();
    const SE3 T_wb = PoseManifold::Pose(s.pose);
    for (const TimedPoint& p : scan.keypoints) {
      const Vec3 q = T_end_inv * (table.Interpolate(p.time) * p.point);
      PlaneAssociation a;
      if (!associator.Associate(q, T_wb * q, &a)) continue;
      a.weight /= config_.frontend.point_noise_sigma;
      blocks->push_back(window_.AddResidualBlock(new PointToPlaneWorld(a), loss, {s.id}));
    }
  };
  const bool degenerate = SolveRounds(
      add_lidar, [&s] { return PoseManifold::Pose(s.pose); }, result);

  // Map update with every preprocessed point, deskewed by the final estimate.
  const auto t_map = std::chrono::steady_clock::now();
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  const double jump = (T_wb.translation() - T_prev.translation()).norm();
  if (!T_wb.translation().allFinite() || jump > config_.max_scan_translation) {
    // Do not pollute the map with a diverged pose; report it.
    std::ostringstream m;
    m << "pose jumped " << jump << " m in one scan (limit " << config_.max_scan_translation
      << " m): estimate diverged";
    result->status = ScanStatus::kFailed;
    result->message = m.str();
  } else {
    const DeskewTable table = Integrate(prev, s.t);
    const SE3 T_end_inv = table.T_wb.back().Inverse();
    std::vector<Vec3> map_points;
    map_points.reserve(scan.points.size());
    for (const TimedPoint& p : scan.points) {
      map_points.push_back(T_wb * (T_end_inv * (table.Interpolate(p.time) * p.point)));
    }
    frontend_.UpdateMap(map_points, T_wb.translation());
  }
  if (degenerate) ReportDegenerate(result);
  result->ms_map = MsSince(t_map);
  Fill(s, ScanStatus::kOk, result);
}

// Window (SPEC §4, §5), as in SingerLio::Slide: the oldest states are marginalised by Schur
// complement into one prior until window_knots − 1 remain, before the new state is added.
void ImuInputLio::Slide(ScanResult* result) {
  while (static_cast<int>(states_.size()) > config_.window_knots - 1) {
    MarginalizeStates(states_.front().ids(), result);
    states_.pop_front();
  }
}

}  // namespace ctlio::lio
