#include "ctlio/solvers/lio/imu_input_lio.h"

#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/imu/preintegrated_imu_factor.h"
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

ImuInputLio::ImuInputLio(const OdometryConfig& config)
    : LioOdometry(config),
      problem_([] {
        ceres::Problem::Options o;
        o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        o.enable_fast_removal = true;
        return o;
      }()),
      lidar_loss_(MakeLidarLoss(config)) {}

ImuInputLio::~ImuInputLio() = default;

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
  // map origin at rest, held constant, which also fixes the gauge.
  auto s = std::make_unique<State>();
  s->t = scan.t_end;
  s->t_ns = scan.end_ns;
  problem_.AddParameterBlock(s->pose, 7, &pose_manifold_);
  problem_.AddParameterBlock(s->velocity, 3);
  problem_.AddParameterBlock(s->bias, 6);
  problem_.SetParameterBlockConstant(s->pose);
  problem_.SetParameterBlockConstant(s->velocity);
  problem_.SetParameterBlockConstant(s->bias);
  std::vector<Vec3> map_points;
  map_points.reserve(scan.points.size());
  for (const TimedPoint& p : scan.points) map_points.push_back(p.point);
  frontend_.UpdateMap(map_points, Vec3::Zero());
  Fill(*s, ScanStatus::kOk, result);
  states_.push_back(std::move(s));
}

void ImuInputLio::Process(const PreparedScan& scan, ScanResult* result) {
  State& prev = *states_.back();
  auto owned = std::make_unique<State>();
  State& s = *owned;
  s.t = scan.t_end;
  s.t_ns = scan.end_ns;

  double max_gap = 0.0;
  const std::vector<ImuSegment> segments = ImuSegments(prev.t, s.t, &max_gap);
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
  PoseManifold::Store(SE3(pred.C, pred.p), s.pose);
  Eigen::Map<Vec3>(s.velocity) = pred.v;
  std::copy(prev.bias, prev.bias + 6, s.bias);

  problem_.AddParameterBlock(s.pose, 7, &pose_manifold_);
  problem_.AddParameterBlock(s.velocity, 3);
  problem_.AddParameterBlock(s.bias, 6);
  problem_.AddResidualBlock(new imu::PreintegratedImuFactor(pim, gravity_map()), nullptr, prev.pose,
                            prev.velocity, prev.bias, s.pose, s.velocity);
  problem_.AddResidualBlock(MakeBiasRandomWalk(config_, s.t - prev.t), nullptr, prev.bias, s.bias);
  result->imu_residuals = 1;

  ceres::Solver::Options options = WindowSolverOptions(config_);
  std::vector<ceres::ResidualBlockId> lidar_blocks;
  PlaneAssociator associator(frontend_.map(), config_.frontend);
  SE3 last_pose = PoseManifold::Pose(s.pose);
  bool degenerate = false;
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  for (int round = 0; round < config_.frontend.max_iterations; ++round) {
    auto t0 = Clock::now();
    for (ceres::ResidualBlockId id : lidar_blocks) problem_.RemoveResidualBlock(id);
    lidar_blocks.clear();
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
      lidar_blocks.push_back(
          problem_.AddResidualBlock(new PointToPlaneWorld(a), lidar_loss_.get(), s.pose));
    }
    result->associations = static_cast<int>(lidar_blocks.size());
    if (static_cast<int>(lidar_blocks.size()) < config_.min_associations) {
      for (ceres::ResidualBlockId id : lidar_blocks) problem_.RemoveResidualBlock(id);
      lidar_blocks.clear();
      degenerate = true;
    }
    result->ms_associate += ms_since(t0);
    t0 = Clock::now();
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem_, &summary);
    result->ms_solve += ms_since(t0);
    result->rounds = round + 1;
    result->solver_iterations += static_cast<int>(summary.iterations.size());
    result->final_cost = summary.final_cost;
    const SE3 T_new = PoseManifold::Pose(s.pose);
    const Vec6 step = (T_new * last_pose.Inverse()).Log();
    last_pose = T_new;
    if (degenerate || (step.head<3>().norm() < config_.frontend.convergence_translation &&
                       step.tail<3>().norm() < config_.frontend.convergence_rotation)) {
      break;
    }
  }

  // Map update with every preprocessed point, deskewed by the final estimate.
  const auto t_map = Clock::now();
  const DeskewTable table = Integrate(prev, s.t);
  const SE3 T_end_inv = table.T_wb.back().Inverse();
  const SE3 T_wb = PoseManifold::Pose(s.pose);
  std::vector<Vec3> map_points;
  map_points.reserve(scan.points.size());
  for (const TimedPoint& p : scan.points) {
    map_points.push_back(T_wb * (T_end_inv * (table.Interpolate(p.time) * p.point)));
  }

  const double jump = (T_wb.translation() - T_prev.translation()).norm();
  if (!T_wb.translation().allFinite() || jump > config_.max_scan_translation) {
    // Do not pollute the map with a diverged pose; report it.
    std::ostringstream m;
    m << "pose jumped " << jump << " m in one scan (limit " << config_.max_scan_translation
      << " m): estimate diverged";
    result->status = ScanStatus::kFailed;
    result->message = m.str();
  } else {
    frontend_.UpdateMap(map_points, T_wb.translation());
  }
  if (degenerate && result->status == ScanStatus::kOk) {
    result->status = ScanStatus::kDegenerate;
    result->message = "only " + std::to_string(result->associations) +
                      " plane associations (need " + std::to_string(config_.min_associations) +
                      "): lidar term dropped for this scan";
  }
  result->ms_map = ms_since(t_map);
  Fill(s, ScanStatus::kOk, result);
  states_.push_back(std::move(owned));
  Slide();
}

// Window (SPEC §4): the `window_knots` newest states are free, the one before is held
// constant; anything older only touches held or removed states, so removing it changes
// nothing in the free states' solution (see SingerLio::Slide for the argument).
void ImuInputLio::Slide() {
  const int free_states = static_cast<int>(states_.size()) - 1;
  if (free_states <= config_.window_knots) return;
  State& hold = *states_[1];
  problem_.SetParameterBlockConstant(hold.pose);
  problem_.SetParameterBlockConstant(hold.velocity);
  problem_.SetParameterBlockConstant(hold.bias);
  State& old = *states_.front();
  problem_.RemoveParameterBlock(old.pose);
  problem_.RemoveParameterBlock(old.velocity);
  problem_.RemoveParameterBlock(old.bias);
  states_.pop_front();
}

}  // namespace ctlio::lio
