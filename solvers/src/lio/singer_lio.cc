#include "ctlio/solvers/lio/singer_lio.h"

#include <ceres/solver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/motion_model.h"
#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/imu/bias_factors.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/solvers/lio/lio_residuals.h"

namespace ctlio::lio {

struct SingerLio::Impl {
  explicit Impl(const OdometryConfig& c) : model(c.qc, c.alpha) {}
  gp::SingerModel<6> model;
};

SingerLio::SingerLio(const OdometryConfig& config)
    : LioOdometry(config),
      problem_([] {
        ceres::Problem::Options o;
        o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        o.enable_fast_removal = true;
        return o;
      }()),
      lidar_loss_(MakeLidarLoss(config)),
      accel_loss_(config.accel_loss_scale > 0 ? new ceres::CauchyLoss(config.accel_loss_scale)
                                              : nullptr),
      impl_(std::make_unique<Impl>(config)) {}

SingerLio::~SingerLio() = default;

void SingerLio::AddKnotBlocks(Knot* k) {
  problem_.AddParameterBlock(k->pose, 7, &pose_manifold_);
  problem_.AddParameterBlock(k->velocity, 6);
  problem_.AddParameterBlock(k->acceleration, 6);
  if (uses_imu()) problem_.AddParameterBlock(k->bias, 6);
}

void SingerLio::SetKnotConstant(Knot* k) {
  problem_.SetParameterBlockConstant(k->pose);
  problem_.SetParameterBlockConstant(k->velocity);
  problem_.SetParameterBlockConstant(k->acceleration);
  if (uses_imu()) problem_.SetParameterBlockConstant(k->bias);
}

SE3 SingerLio::PoseAt(const Knot& a, const Knot& b, double tau) const {
  const gp::GpInterpolator interp(impl_->model, a.t, b.t, std::clamp(tau, a.t, b.t));
  SE3 T_rm;
  interp.Pose(gp::ReadKnotState(a.pose, a.velocity, a.acceleration),
              gp::ReadKnotState(b.pose, b.velocity, b.acceleration), &T_rm, nullptr, nullptr);
  return T_rm.Inverse();
}

void SingerLio::Fill(const Knot& k, ScanResult* result) const {
  result->T_mr = PoseManifold::Pose(k.pose).Inverse();
  // ϖ is minus the body twist [v; ω] in the robot frame (SPEC §1).
  result->velocity = -Eigen::Map<const Vec6>(k.velocity);
  result->bias = Eigen::Map<const Vec6>(k.bias);
}

void SingerLio::Initialise(const PreparedScan& scan, ScanResult* result) {
  // Still at start (checked by the gravity initialisation): knot 0 is the map origin at rest,
  // held constant, which fixes the gauge; its biases start at zero (their prior mean).
  Eigen::Quaterniond q(C_mi_);
  C_mi_block_[0] = q.x();
  C_mi_block_[1] = q.y();
  C_mi_block_[2] = q.z();
  C_mi_block_[3] = q.w();
  if (config_.method == LioMethod::kSingerLio) {
    problem_.AddParameterBlock(C_mi_block_, 4, &rotation_manifold_);
    if (!config_.estimate_gravity) problem_.SetParameterBlockConstant(C_mi_block_);
  }
  auto k = std::make_unique<Knot>();
  k->t = scan.t_end;
  k->t_ns = scan.end_ns;
  AddKnotBlocks(k.get());
  SetKnotConstant(k.get());
  std::vector<Vec3> map_points;
  map_points.reserve(scan.points.size());
  for (const TimedPoint& p : scan.points) map_points.push_back(p.point);
  frontend_.UpdateMap(map_points, Vec3::Zero());
  Fill(*k, result);
  knots_.push_back(std::move(k));
}

void SingerLio::Process(const PreparedScan& scan, ScanResult* result) {
  Knot& prev = *knots_.back();
  auto owned = std::make_unique<Knot>();
  Knot& k = *owned;
  k.t = scan.t_end;
  k.t_ns = scan.end_ns;
  const double dt = k.t - prev.t;

  // IMU over the interval: gap check and the samples to use as measurements.
  std::vector<ImuSample> imu;
  if (uses_imu()) {
    double max_gap = 0.0;
    ImuSegments(prev.t, k.t, &max_gap);
    imu = ImuSamples(prev.t, k.t);
    if (max_gap > config_.max_imu_gap) {
      std::ostringstream m;
      m << "IMU gap of " << max_gap << " s (limit " << config_.max_imu_gap
        << " s): the GP prior bridges it";
      result->status = ScanStatus::kImuGap;
      result->message = m.str();
    }
  }

  // Initial guess: constant body velocity from the previous knot; with a gyro, its newest
  // sample gives the angular part (ϖ_φ = −(ω_meas − b_g), SPEC §1).
  Vec6 w = Eigen::Map<const Vec6>(prev.velocity);
  if (uses_imu() && !imu.empty()) {
    w.tail<3>() = -(imu.back().gyro - Eigen::Map<const Vec3>(prev.bias + 3));
  }
  PoseManifold::Store(SE3::Exp(dt * w) * PoseManifold::Pose(prev.pose), k.pose);
  Eigen::Map<Vec6>(k.velocity) = w;
  Eigen::Map<Vec6>(k.acceleration).setZero();
  std::copy(prev.bias, prev.bias + 6, k.bias);
  AddKnotBlocks(&k);

  // GP prior between the knots (SPEC §2).
  problem_.AddResidualBlock(new gp::SingerPrior(impl_->model, dt), nullptr, prev.pose,
                            prev.velocity, prev.acceleration, k.pose, k.velocity, k.acceleration);
  // IMU as a measurement of the interpolated state (SPEC §3).
  if (uses_imu()) {
    problem_.AddResidualBlock(MakeBiasRandomWalk(config_, dt), nullptr, prev.bias, k.bias);
    const Mat3 gyro_cov = config_.gyro_variance * Mat3::Identity();
    const Mat3 accel_cov = config_.accel_variance * Mat3::Identity();
    const imu::AccelModel accel_model = config_.exact_specific_force
                                            ? imu::AccelModel::kSpecificForce
                                            : imu::AccelModel::kBodyCentric;
    for (const ImuSample& s : imu) {
      const double tau = Seconds(s.t_ns);
      problem_.AddResidualBlock(
          new imu::ImuGyroMeasurement(impl_->model, prev.t, k.t, tau, s.gyro, gyro_cov), nullptr,
          prev.pose, prev.velocity, prev.acceleration, k.pose, k.velocity, k.acceleration,
          prev.bias, k.bias);
      ++result->imu_residuals;
      if (config_.method == LioMethod::kSingerLio) {
        problem_.AddResidualBlock(
            new imu::ImuAccelMeasurement(impl_->model, prev.t, k.t, tau, s.accel, accel_cov,
                                         config_.gravity, accel_model),
            accel_loss_.get(), prev.pose, prev.velocity, prev.acceleration, k.pose, k.velocity,
            k.acceleration, prev.bias, k.bias, C_mi_block_);
        ++result->imu_residuals;
      }
    }
  }

  // Lidar: interpolated point-to-plane, re-associated every round (SPEC §4).
  const ceres::Solver::Options options = WindowSolverOptions(config_);
  std::vector<ceres::ResidualBlockId> lidar_blocks;
  PlaneAssociator associator(frontend_.map(), config_.frontend);
  SE3 last_pose = PoseManifold::Pose(k.pose);
  bool degenerate = false;
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  for (int round = 0; round < config_.frontend.max_iterations; ++round) {
    auto t0 = Clock::now();
    for (ceres::ResidualBlockId id : lidar_blocks) problem_.RemoveResidualBlock(id);
    lidar_blocks.clear();
    // One shared interpolation per distinct point time (a lidar firing), see lio_residuals.h.
    std::shared_ptr<const SharedInterpolatedPose> shared;
    double shared_tau = -1.0;
    SE3 T_mr_tau;
    for (const TimedPoint& p : scan.keypoints) {
      const double tau = std::clamp(p.time, prev.t, k.t);
      if (!shared || tau != shared_tau) {
        shared = std::make_shared<const SharedInterpolatedPose>(impl_->model, prev.t, k.t, tau);
        shared_tau = tau;
        const double* blocks[6] = {prev.pose, prev.velocity, prev.acceleration,
                                   k.pose,    k.velocity,    k.acceleration};
        shared->Pose(blocks, &T_mr_tau, nullptr, nullptr);
        T_mr_tau = T_mr_tau.Inverse();
      }
      PlaneAssociation a;
      if (!associator.Associate(p.point, T_mr_tau * p.point, &a)) continue;
      a.weight /= config_.frontend.point_noise_sigma;
      lidar_blocks.push_back(problem_.AddResidualBlock(
          new FiringPointToPlane(shared, a), lidar_loss_.get(), prev.pose, prev.velocity,
          prev.acceleration, k.pose, k.velocity, k.acceleration));
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
    const SE3 T_new = PoseManifold::Pose(k.pose);
    const Vec6 step = (T_new * last_pose.Inverse()).Log();
    last_pose = T_new;
    if (degenerate || (step.head<3>().norm() < config_.frontend.convergence_translation &&
                       step.tail<3>().norm() < config_.frontend.convergence_rotation)) {
      break;
    }
  }

  // Map update: every preprocessed point at its own interpolated pose.
  const auto t_map = Clock::now();
  const SE3 T_mr_end = PoseManifold::Pose(k.pose).Inverse();
  const SE3 T_mr_prev = PoseManifold::Pose(prev.pose).Inverse();
  const double jump = (T_mr_end.translation() - T_mr_prev.translation()).norm();
  if (!T_mr_end.translation().allFinite() || jump > config_.max_scan_translation) {
    std::ostringstream m;
    m << "pose jumped " << jump << " m in one scan (limit " << config_.max_scan_translation
      << " m): estimate diverged";
    result->status = ScanStatus::kFailed;
    result->message = m.str();
  } else {
    std::vector<Vec3> map_points;
    map_points.reserve(scan.points.size());
    double last_tau = -1.0;
    SE3 T_mr_tau;
    for (const TimedPoint& p : scan.points) {
      if (p.time != last_tau) {  // points of one firing share the interpolation
        T_mr_tau = PoseAt(prev, k, p.time);
        last_tau = p.time;
      }
      map_points.push_back(T_mr_tau * p.point);
    }
    frontend_.UpdateMap(map_points, T_mr_end.translation());
  }
  if (degenerate && result->status == ScanStatus::kOk) {
    result->status = ScanStatus::kDegenerate;
    result->message = "only " + std::to_string(result->associations) +
                      " plane associations (need " + std::to_string(config_.min_associations) +
                      "): lidar term dropped, prior" + (uses_imu() ? " + IMU" : "") +
                      " carry the state";
  }
  result->ms_map = ms_since(t_map);
  Fill(k, result);
  knots_.push_back(std::move(owned));
  Slide();
}

// Window of SPEC §4: the `window_knots` newest knots are free and the one before is held
// constant. Once a knot is held, every factor that touches only it and older knots is constant
// and has no effect on the free knots: its marginal prior would act on a held block. So the
// oldest (held) knot can be removed with its factors without changing the solution, and the
// next one becomes the held knot.
void SingerLio::Slide() {
  const int free_knots = static_cast<int>(knots_.size()) - 1;
  if (free_knots <= config_.window_knots) return;
  SetKnotConstant(knots_[1].get());
  Knot& old = *knots_.front();
  problem_.RemoveParameterBlock(old.pose);
  problem_.RemoveParameterBlock(old.velocity);
  problem_.RemoveParameterBlock(old.acceleration);
  if (uses_imu()) problem_.RemoveParameterBlock(old.bias);
  knots_.pop_front();
}

}  // namespace ctlio::lio
