#include "ctlio/euroc/fusion.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <random>

#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/gp/vector_prior.h"
#include "ctlio/factors/imu/bias_factors.h"
#include "ctlio/factors/imu/gravity_initialization.h"
#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/factors/priors/linear_measurement.h"
#include "ctlio/factors/priors/position_measurement.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::euroc {
namespace {

using imu::ImuSample;
using Clock = std::chrono::steady_clock;

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

double Seconds(std::int64_t a, std::int64_t b) { return 1e-9 * static_cast<double>(b - a); }
double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

ceres::Solver::Options Options(const SolveOptions& o) {
  ceres::Solver::Options s;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  s.max_num_iterations = o.max_iterations;
  s.minimizer_progress_to_stdout = o.verbose;
  s.num_threads = 1;
  s.function_tolerance = 1e-8;
  return s;
}

Mat3 PositionCovariance(const SolveOptions& o) {
  return o.position_sigma * o.position_sigma * Mat3::Identity();
}

// Covariance blocks in the tangent space for the listed parameter blocks.
bool TangentCovariances(ceres::Problem* problem, const std::vector<double*>& blocks,
                        std::vector<Eigen::MatrixXd>* out) {
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::SPARSE_QR;
  co.num_threads = 1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (double* b : blocks) pairs.emplace_back(b, b);
  if (!cov.Compute(pairs, problem)) return false;
  out->clear();
  for (double* b : blocks) {
    const int n = problem->ParameterBlockTangentSize(b);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(n, n);
    cov.GetCovarianceBlockInTangentSpace(b, b, m.data());
    out->push_back(m);
  }
  return true;
}

// Attitude initial guess: gyro dead reckoning from the ground-truth attitude of the first knot,
// with the still-start gyro bias.
std::vector<Mat3> DeadReckonAttitude(const std::vector<ImuSample>& imu,
                                     const std::vector<Position>& seg, const ImuNoiseModel& noise) {
  std::vector<Mat3> C(seg.size());
  C[0] = seg[0].truth.x.C;
  imu::ImuNoise n;
  n.gyro_noise_density = n.accel_noise_density = 1.0;
  Vec6 b = Vec6::Zero();
  b.tail<3>() = noise.gyro_bias;
  for (std::size_t i = 1; i < seg.size(); ++i) {
    imu::PreintegratedImu pim(b, n);
    imu::IntegrateInterval(imu, seg[i - 1].t_ns, seg[i].t_ns, &pim);
    C[i] = so3::Normalize(C[i - 1] * pim.delta_rotation());
  }
  return C;
}

Vec6 InitialBias(const ImuNoiseModel& noise) {
  Vec6 b = Vec6::Zero();
  b.tail<3>() = noise.gyro_bias;
  return b;
}

Mat6 InitialBiasCovariance() {
  Vec6 d;
  d << 0.1, 0.1, 0.1, 0.01, 0.01, 0.01;  // SPEC §4 initial bias variances
  return d.asDiagonal();
}

// Whitened accelerometer errors s = |e|² at the solution: how many a loss would down-weight.
void LogAccelErrors(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& blocks,
                    const ceres::Solver::Summary& summary) {
  ceres::Problem::EvaluateOptions eo;
  eo.residual_blocks = blocks;
  eo.apply_loss_function = false;
  std::vector<double> r, s2;
  problem->Evaluate(eo, nullptr, &r, nullptr, nullptr);
  for (std::size_t b = 0; b + 2 < r.size(); b += 3) {
    s2.push_back(r[b] * r[b] + r[b + 1] * r[b + 1] + r[b + 2] * r[b + 2]);
  }
  if (s2.empty()) return;
  std::sort(s2.begin(), s2.end());
  const auto above = std::count_if(s2.begin(), s2.end(), [](double v) { return v > 1.0; });
  LOG(INFO) << "whitened accel |e|^2: median " << s2[s2.size() / 2] << ", 90% "
            << s2[s2.size() * 9 / 10]
            << ", fraction > 1: " << static_cast<double>(above) / s2.size() << "; iterations "
            << summary.iterations.size() - 1 << ", "
            << ceres::TerminationTypeToString(summary.termination_type);
}

}  // namespace

Metrics Evaluate(const std::vector<Position>& seg, const Estimate& e) {
  Metrics m;
  m.has_rotation = !e.C_wb.empty();
  double sp = 0, sr = 0, st = 0, sn = 0;
  int nn = 0;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    const Vec3 d = e.p[i] - seg[i].truth.x.p;
    sp += d.squaredNorm();
    if (m.has_rotation) {
      sr += so3::Log(e.C_wb[i].transpose() * seg[i].truth.x.C).squaredNorm();
      const double tilt = imu::TiltError(e.C_wb[i].transpose(), seg[i].truth.x.C);
      st += tilt * tilt;
    }
    if (!e.P.empty() && e.P[i].allFinite()) {
      sn += d.dot(e.P[i].ldlt().solve(d));
      ++nn;
    }
  }
  m.pos_rmse = std::sqrt(sp / seg.size());
  if (m.has_rotation) {
    m.rot_rmse_deg = std::sqrt(sr / seg.size()) * kRadToDeg;
    m.tilt_rmse_deg = std::sqrt(st / seg.size()) * kRadToDeg;
  }
  m.has_nees = nn > 0;
  if (m.has_nees) m.nees = sn / nn;
  return m;
}

std::vector<Position> NoisyPositions(const std::vector<io::GroundTruthState>& gt,
                                     const std::vector<ImuSample>& imu, int stride, double sigma,
                                     unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, sigma);
  std::vector<Position> all;
  // Warn about gaps longer than 1.5 × the nominal spacing of the kept rows.
  const double max_gap = 1.5 * stride * Seconds(gt.front().t_ns, gt.back().t_ns) / (gt.size() - 1);
  for (std::size_t i = 0; i < gt.size(); i += stride) {
    if (gt[i].t_ns < imu.front().t_ns || gt[i].t_ns > imu.back().t_ns) continue;
    if (!all.empty() && Seconds(all.back().t_ns, gt[i].t_ns) > max_gap) {
      LOG(WARNING) << "gap of " << Seconds(all.back().t_ns, gt[i].t_ns) << " s in positions";
    }
    all.push_back({gt[i].t_ns, gt[i].x.p + Vec3(gauss(rng), gauss(rng), gauss(rng)), gt[i]});
  }
  return all;
}

std::vector<Position> Slice(const std::vector<Position>& all, double from_s, double length_s) {
  std::vector<Position> out;
  const std::int64_t t0 = all.front().t_ns + static_cast<std::int64_t>(from_s * 1e9);
  const std::int64_t t1 = t0 + static_cast<std::int64_t>(length_s * 1e9);
  for (const Position& p : all) {
    if (p.t_ns >= t0 && p.t_ns <= t1) out.push_back(p);
  }
  return out;
}

ImuNoiseModel StillStartNoise(const std::vector<ImuSample>& imu) {
  ImuNoiseModel noise;
  const std::int64_t second = 1'000'000'000;
  const imu::GravityInitialization g = imu::InitializeGravity(imu, imu.front().t_ns, second);
  Vec3 wsum = Vec3::Zero();
  int cnt = 0;
  for (const ImuSample& s : imu) {
    if (s.t_ns >= imu.front().t_ns + second) break;
    wsum += s.gyro;
    ++cnt;
  }
  noise.gyro_bias = wsum / cnt;
  double wsq = 0;
  for (int k = 0; k < cnt; ++k) wsq += (imu[k].gyro - noise.gyro_bias).squaredNorm();
  noise.accel_var = g.accel_std * g.accel_std / 3.0;
  noise.gyro_var = wsq / cnt / 3.0;
  noise.sample_dt = Seconds(imu.front().t_ns, imu.back().t_ns) / (imu.size() - 1);
  return noise;
}

Estimate PositionsOnly(const std::vector<Position>& seg, double qc, const SolveOptions& o) {
  const auto start = Clock::now();
  const gp::SingerModel<3> model = gp::SingerModel<3>::Wnoj(Eigen::Vector3d::Constant(qc));
  std::vector<Eigen::Matrix<double, 9, 1>> x(seg.size(), Eigen::Matrix<double, 9, 1>::Zero());
  ceres::Problem problem;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    x[i].head<3>() = seg[i].measured;
    problem.AddResidualBlock(
        LinearMeasurement<3, 9>::Leading(seg[i].measured, PositionCovariance(o)), nullptr,
        x[i].data());
    if (i > 0) {
      problem.AddResidualBlock(
          gp::MakeSingerVectorPrior<3>(model, Seconds(seg[i - 1].t_ns, seg[i].t_ns)), nullptr,
          x[i - 1].data(), x[i].data());
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(Options(o), &problem, &summary);
  Estimate e;
  for (const auto& xi : x) {
    e.p.push_back(xi.head<3>());
    e.v.push_back(xi.segment<3>(3));
  }
  std::vector<double*> blocks;
  for (auto& xi : x) blocks.push_back(xi.data());
  std::vector<Eigen::MatrixXd> covs;
  if (o.nees && TangentCovariances(&problem, blocks, &covs)) {
    for (const auto& c : covs) e.P.push_back(c.topLeftCorner<3, 3>());
  }
  e.seconds = Since(start);
  return e;
}

Estimate ImuAsInput(const std::vector<ImuSample>& imu, const std::vector<Position>& seg,
                    const ImuNoiseModel& noise, const Estimate& init, const SolveOptions& o) {
  const auto start = Clock::now();
  const std::size_t n = seg.size();
  const std::vector<Mat3> C0 = DeadReckonAttitude(imu, seg, noise);
  std::vector<std::array<double, 7>> pose(n);
  std::vector<Vec3> vel(n);
  std::vector<Vec6> bias(n, InitialBias(noise));
  imu::ImuNoise imu_noise;
  imu_noise.accel_noise_density = std::sqrt(noise.accel_var * noise.sample_dt);
  imu_noise.gyro_noise_density = std::sqrt(noise.gyro_var * noise.sample_dt);
  ceres::Problem problem;
  auto* pose_manifold = new PoseManifold;  // owned by the problem
  for (std::size_t i = 0; i < n; ++i) {
    PoseManifold::Store(SE3(C0[i], init.p[i]), pose[i].data());
    vel[i] = init.v[i];
    problem.AddParameterBlock(pose[i].data(), 7, pose_manifold);
    problem.AddResidualBlock(new PositionMeasurement(seg[i].measured, PositionCovariance(o),
                                                     PoseConvention::kWorldFromBody),
                             nullptr, pose[i].data());
  }
  problem.AddResidualBlock(new imu::BiasPrior(InitialBias(noise), InitialBiasCovariance()), nullptr,
                           bias[0].data());
  for (std::size_t i = 1; i < n; ++i) {
    imu::PreintegratedImu pim(bias[i - 1], imu_noise);
    imu::IntegrateInterval(imu, seg[i - 1].t_ns, seg[i].t_ns, &pim);
    problem.AddResidualBlock(new imu::PreintegratedImuFactor(pim, Vec3(0, 0, -kGravity)), nullptr,
                             pose[i - 1].data(), vel[i - 1].data(), bias[i - 1].data(),
                             pose[i].data(), vel[i].data());
    problem.AddResidualBlock(new imu::BiasRandomWalk(noise.accel_rw_psd, noise.gyro_rw_psd,
                                                     Seconds(seg[i - 1].t_ns, seg[i].t_ns)),
                             nullptr, bias[i - 1].data(), bias[i].data());
  }
  ceres::Solver::Summary summary;
  ceres::Solve(Options(o), &problem, &summary);
  LOG(INFO) << "IMU as input: " << summary.BriefReport();
  Estimate e;
  for (std::size_t i = 0; i < n; ++i) {
    const SE3 T = PoseManifold::Pose(pose[i].data());
    e.p.push_back(T.translation());
    e.C_wb.push_back(T.rotation());
  }
  std::vector<double*> blocks;
  for (auto& p : pose) blocks.push_back(p.data());
  std::vector<Eigen::MatrixXd> covs;
  if (o.nees && TangentCovariances(&problem, blocks, &covs)) {
    for (std::size_t i = 0; i < n; ++i) {
      // p ← p + ρ + φ^p: Cov(p) = [I, −p^] Σ [I, −p^]ᵀ.
      Eigen::Matrix<double, 3, 6> A;
      A << Mat3::Identity(), -so3::Hat(e.p[i]);
      e.P.push_back(A * covs[i] * A.transpose());
    }
  }
  e.seconds = Since(start);
  return e;
}

Estimate ImuAsMeasurement(const std::vector<ImuSample>& imu, const std::vector<Position>& seg,
                          const ImuNoiseModel& noise, const Estimate& init,
                          const gp::SingerModel<6>& model, imu::AccelModel accel_model,
                          const SolveOptions& o) {
  const auto start = Clock::now();
  const std::size_t n = seg.size();
  const std::vector<Mat3> C0 = DeadReckonAttitude(imu, seg, noise);
  std::vector<std::array<double, 7>> pose(n);
  std::vector<Vec6> vel(n), acc(n, Vec6::Zero()), bias(n, InitialBias(noise));
  double q_mi[4];
  RotationManifold::Store(Mat3::Identity(), q_mi);
  ceres::Problem problem;
  auto* pose_manifold = new PoseManifold;
  for (std::size_t i = 0; i < n; ++i) {
    const SE3 T_rm = SE3(C0[i], init.p[i]).Inverse();
    PoseManifold::Store(T_rm, pose[i].data());
    // ϖ = −[v_b; ω]: v_b = C_rm v_world, ω from the nearest gyro sample.
    auto it = std::lower_bound(imu.begin(), imu.end(), seg[i].t_ns,
                               [](const ImuSample& s, std::int64_t t) { return s.t_ns < t; });
    const Vec3 omega = it->gyro - noise.gyro_bias;
    vel[i] << -(T_rm.rotation() * init.v[i]), -omega;
    problem.AddParameterBlock(pose[i].data(), 7, pose_manifold);
    problem.AddResidualBlock(new PositionMeasurement(seg[i].measured, PositionCovariance(o),
                                                     PoseConvention::kBodyFromWorld),
                             nullptr, pose[i].data());
  }
  problem.AddParameterBlock(q_mi, 4, new RotationManifold);
  problem.SetParameterBlockConstant(q_mi);
  problem.AddResidualBlock(new imu::BiasPrior(InitialBias(noise), InitialBiasCovariance()), nullptr,
                           bias[0].data());
  // One wrapper for every accelerometer residual (the problem deletes it once), so that the
  // loss can be switched on after a warm start without the loss.
  const bool cauchy = o.cauchy_scale > 0;
  auto* accel_loss = new ceres::LossFunctionWrapper(
      cauchy && !o.cauchy_warm_start ? new ceres::CauchyLoss(o.cauchy_scale) : nullptr,
      ceres::TAKE_OWNERSHIP);
  std::vector<ceres::ResidualBlockId> accel_blocks;
  const Mat3 accel_cov = noise.accel_var * Mat3::Identity();
  const Mat3 gyro_cov = noise.gyro_var * Mat3::Identity();
  std::size_t j = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const double t0 = 0.0, t1 = Seconds(seg[i - 1].t_ns, seg[i].t_ns);
    double* k0[] = {pose[i - 1].data(), vel[i - 1].data(), acc[i - 1].data()};
    double* k1[] = {pose[i].data(), vel[i].data(), acc[i].data()};
    problem.AddResidualBlock(new gp::SingerPrior(model, t1), nullptr, k0[0], k0[1], k0[2], k1[0],
                             k1[1], k1[2]);
    problem.AddResidualBlock(new imu::BiasRandomWalk(noise.accel_rw_psd, noise.gyro_rw_psd, t1),
                             nullptr, bias[i - 1].data(), bias[i].data());
    while (j < imu.size() && imu[j].t_ns < seg[i - 1].t_ns) ++j;
    for (; j < imu.size() && imu[j].t_ns < seg[i].t_ns; ++j) {
      const double tau = Seconds(seg[i - 1].t_ns, imu[j].t_ns);
      problem.AddResidualBlock(
          new imu::ImuGyroMeasurement(model, t0, t1, tau, imu[j].gyro, gyro_cov), nullptr, k0[0],
          k0[1], k0[2], k1[0], k1[1], k1[2], bias[i - 1].data(), bias[i].data());
      // The paper: Cauchy loss, scale 1, on the whitened accelerometer error.
      accel_blocks.push_back(
          problem.AddResidualBlock(new imu::ImuAccelMeasurement(model, t0, t1, tau, imu[j].accel,
                                                                accel_cov, kGravity, accel_model),
                                   accel_loss, k0[0], k0[1], k0[2], k1[0], k1[1], k1[2],
                                   bias[i - 1].data(), bias[i].data(), q_mi));
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(Options(o), &problem, &summary);
  LOG(INFO) << "IMU as measurement" << (cauchy && o.cauchy_warm_start ? " (no loss)" : "") << ": "
            << summary.BriefReport();
  if (cauchy && o.cauchy_warm_start) {
    accel_loss->Reset(new ceres::CauchyLoss(o.cauchy_scale), ceres::TAKE_OWNERSHIP);
    ceres::Solve(Options(o), &problem, &summary);
    LOG(INFO) << "IMU as measurement (Cauchy " << o.cauchy_scale << "): " << summary.BriefReport();
  }
  LogAccelErrors(&problem, accel_blocks, summary);
  Estimate e;
  for (std::size_t i = 0; i < n; ++i) {
    const SE3 T_mr = PoseManifold::Pose(pose[i].data()).Inverse();
    e.p.push_back(T_mr.translation());
    e.C_wb.push_back(T_mr.rotation());
  }
  std::vector<double*> blocks;
  for (auto& p : pose) blocks.push_back(p.data());
  std::vector<Eigen::MatrixXd> covs;
  if (o.nees && TangentCovariances(&problem, blocks, &covs)) {
    for (std::size_t i = 0; i < n; ++i) {
      // p ← p − C_mr ρ.
      const Mat3& C_mr = e.C_wb[i];
      e.P.push_back(C_mr * covs[i].topLeftCorner<3, 3>() * C_mr.transpose());
    }
  }
  e.seconds = Since(start);
  return e;
}

}  // namespace ctlio::euroc
