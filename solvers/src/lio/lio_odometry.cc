#include "ctlio/solvers/lio/lio_odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/imu/gravity_initialization.h"
#include "ctlio/solvers/lio/imu_input_lio.h"
#include "ctlio/solvers/lio/lio_residuals.h"
#include "ctlio/solvers/lio/singer_lio.h"

namespace ctlio::lio {

namespace {
SlidingWindowOptions WindowOptions(const OdometryConfig& config) {
  SlidingWindowOptions o;
  o.solver = WindowSolverOptions(config);
  return o;
}
double ThreadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}
// Time order groups the points of one firing, whose interpolated pose the pipelines share. A
// sweep usually arrives in firing order already: then the (allocating) sort is skipped.
void SortByTime(std::vector<TimedPoint>* points) {
  const auto by_time = [](const TimedPoint& a, const TimedPoint& b) { return a.time < b.time; };
  if (!std::is_sorted(points->begin(), points->end(), by_time)) {
    std::stable_sort(points->begin(), points->end(), by_time);
  }
}
}  // namespace

double LioOdometry::MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

LioOdometry::LioOdometry(const OdometryConfig& config)
    : frontend_(config.frontend), config_(config), window_(WindowOptions(config)) {
  config_.Validate();
}

ceres::LossFunction* LioOdometry::NewLidarLoss() const { return MakeLidarLoss(config_).release(); }

bool LioOdometry::SolveRounds(const AddLidarResiduals& add_lidar,
                              const std::function<SE3()>& newest_pose, ScanResult* result) {
  using Clock = std::chrono::steady_clock;
  std::vector<ceres::ResidualBlockId> lidar_blocks;
  SE3 last_pose = newest_pose();
  bool degenerate = false;
  for (int round = 0; round < config_.frontend.max_iterations; ++round) {
    auto t0 = Clock::now();
    for (ceres::ResidualBlockId id : lidar_blocks) window_.RemoveResidualBlock(id);
    lidar_blocks.clear();
    // One loss object per round, shared by its residuals: the window owns (and ref-counts) it.
    std::unique_ptr<ceres::LossFunction> loss(NewLidarLoss());
    add_lidar(loss.get(), &lidar_blocks);
    // Once a residual used it, Ceres owns the loss (and deletes it with the last such residual,
    // possibly right below).
    if (!lidar_blocks.empty()) loss.release();
    result->associations = static_cast<int>(lidar_blocks.size());
    if (static_cast<int>(lidar_blocks.size()) < config_.min_associations) {
      for (ceres::ResidualBlockId id : lidar_blocks) window_.RemoveResidualBlock(id);
      lidar_blocks.clear();
      degenerate = true;
    }
    result->ms_associate += MsSince(t0);
    t0 = Clock::now();
    const ceres::Solver::Summary summary = window_.Solve();
    result->ms_solve += MsSince(t0);
    result->rounds = round + 1;
    result->solver_iterations += static_cast<int>(summary.iterations.size());
    result->final_cost = summary.final_cost;
    const SE3 T_new = newest_pose();
    const Vec6 step = (T_new * last_pose.Inverse()).Log();
    last_pose = T_new;
    if (degenerate || (step.head<3>().norm() < config_.frontend.convergence_translation &&
                       step.tail<3>().norm() < config_.frontend.convergence_rotation)) {
      break;
    }
  }
  return degenerate;
}

void LioOdometry::MarginalizeStates(const std::vector<StateId>& ids, ScanResult* result) {
  const auto t0 = std::chrono::steady_clock::now();
  last_marginalization_ = window_.Marginalize(ids);
  ++num_marginalizations_;
  result->ms_marginalize += MsSince(t0);
}

void LioOdometry::ReportDegenerate(ScanResult* result) const {
  if (result->status != ScanStatus::kOk) return;
  result->status = ScanStatus::kDegenerate;
  result->message = "only " + std::to_string(result->associations) + " plane associations (need " +
                    std::to_string(config_.min_associations) +
                    "): lidar term dropped for this scan, the prior" +
                    (uses_imu() ? " and the IMU carry" : " carries") + " the state";
}

void LioOdometry::AddImu(const ImuSample& s) {
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    throw std::invalid_argument(
        "LioOdometry::AddImu: non-finite IMU sample at t = " + std::to_string(s.t_ns) + " ns");
  }
  if (!imu_.empty()) {
    if (s.t_ns == imu_.back().t_ns) {
      ++duplicate_imu_;  // documented recovery: keep the first of two equal stamps
      return;
    }
    if (s.t_ns < imu_.back().t_ns) {
      throw std::invalid_argument("LioOdometry::AddImu: IMU time goes backwards (" +
                                  std::to_string(s.t_ns) + " ns after " +
                                  std::to_string(imu_.back().t_ns) + " ns)");
    }
  }
  imu_.push_back(s);
}

std::vector<ImuSegment> LioOdometry::ImuSegments(double t_a, double t_b, double* max_gap) const {
  std::vector<ImuSegment> out;
  double gap = 0.0;
  if (imu_.empty() || t_b <= t_a) {
    if (max_gap) *max_gap = imu_.empty() ? t_b - t_a : 0.0;
    return out;
  }
  // Index of the last sample at or before t_a (or the first sample).
  size_t i = 0;
  while (i + 1 < imu_.size() && Seconds(imu_[i + 1].t_ns) <= t_a) ++i;
  double t = t_a;
  double last_sample_time = std::min(Seconds(imu_[i].t_ns), t_a);
  while (t < t_b) {
    const double t_next = (i + 1 < imu_.size()) ? std::min(Seconds(imu_[i + 1].t_ns), t_b) : t_b;
    if (t_next > t) {
      ImuSegment seg;
      seg.gyro = imu_[i].gyro;
      seg.accel = imu_[i].accel;
      seg.t_begin = t;
      seg.dt = t_next - t;
      out.push_back(seg);
    }
    if (i + 1 < imu_.size() && Seconds(imu_[i + 1].t_ns) <= t_b) {
      gap = std::max(gap, Seconds(imu_[i + 1].t_ns) - last_sample_time);
      last_sample_time = Seconds(imu_[i + 1].t_ns);
      ++i;
    }
    t = t_next;
    if (i + 1 >= imu_.size()) {
      // No sample after this one: hold it to t_b (an IMU gap at the end of the stream).
      if (t < t_b) {
        ImuSegment seg;
        seg.gyro = imu_[i].gyro;
        seg.accel = imu_[i].accel;
        seg.t_begin = t;
        seg.dt = t_b - t;
        out.push_back(seg);
      }
      break;
    }
  }
  gap = std::max(gap, t_b - last_sample_time);
  if (max_gap) *max_gap = gap;
  return out;
}

std::vector<ImuSample> LioOdometry::ImuSamples(double t_a, double t_b) const {
  std::vector<ImuSample> out;
  for (const ImuSample& s : imu_) {
    const double t = Seconds(s.t_ns);
    if (t > t_a && t <= t_b) out.push_back(s);
  }
  return out;
}

void LioOdometry::TrimImu(double t) {
  while (imu_.size() > 1 && Seconds(imu_[1].t_ns) <= t) imu_.pop_front();
}

// SPEC §3: gravity initialisation from the accelerometer while still (imu::InitializeGravity,
// which also judges stillness). The map frame is the robot frame at the start, so its C_mi is
// the map's. Uses the last gravity_init_duration seconds of IMU up to the first scan end.
bool LioOdometry::InitialiseGravity(double t_end, std::string* message) {
  std::vector<ImuSample> samples(imu_.begin(), imu_.end());
  if (samples.empty()) {
    *message = "gravity initialisation: no IMU samples before the first scan end";
    return false;
  }
  const int64_t end_ns = origin_ns_ + static_cast<int64_t>(std::llround(t_end * 1e9));
  const int64_t t0_ns =
      std::max(samples.front().t_ns,
               end_ns - static_cast<int64_t>(std::llround(config_.gravity_init_duration * 1e9)));
  imu::GravityInitializationOptions options;
  options.gravity = config_.gravity;
  options.max_block_accel_deviation = config_.gravity_init_max_std;
  options.min_samples = 10;
  try {
    const imu::GravityInitialization g =
        imu::InitializeGravity(samples, t0_ns, end_ns - t0_ns + 1, options);
    C_mi_ = g.C_mi;
  } catch (const std::exception& e) {
    *message = std::string("gravity initialisation failed: ") + e.what();
    return false;
  }
  return true;
}

ScanResult LioOdometry::AddScan(const LidarScan& scan) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuMs();
  if (scan.points.size() != scan.times_ns.size()) {
    throw std::invalid_argument("LioOdometry::AddScan: scan ending at " +
                                std::to_string(scan.end_ns) + " ns has " +
                                std::to_string(scan.points.size()) + " points but " +
                                std::to_string(scan.times_ns.size()) + " times");
  }
  if (scan.end_ns <= scan.begin_ns) {
    throw std::invalid_argument("LioOdometry::AddScan: scan end " + std::to_string(scan.end_ns) +
                                " ns is not after its begin " + std::to_string(scan.begin_ns));
  }
  if (have_origin_ && scan.end_ns <= last_scan_end_ns_) {
    throw std::invalid_argument(
        "LioOdometry::AddScan: scan ending at " + std::to_string(scan.end_ns) +
        " ns is not after the previous one (" + std::to_string(last_scan_end_ns_) + " ns)");
  }
  if (!have_origin_) {
    origin_ns_ = scan.begin_ns;
    have_origin_ = true;
  }
  const double t_prev = initialised_ ? Seconds(last_scan_end_ns_) : Seconds(scan.begin_ns);

  PreparedScan prepared;
  prepared.t_begin = Seconds(scan.begin_ns);
  prepared.t_end = Seconds(scan.end_ns);
  prepared.end_ns = scan.end_ns;
  // Range gate and voxel subsampling in the lidar frame first (one pass, no copy of the up to
  // 230 000 raw returns of a 128-beam sweep); Preprocess then repeats both on the few thousand
  // survivors in the robot frame (idempotent up to the extrinsic's shift of the voxel grid).
  const std::vector<size_t> kept =
      RangeGatedVoxelIndices(scan.points, frontend_.NextVoxelSize(), config_.frontend.min_range,
                             config_.frontend.max_range);
  std::vector<TimedPoint> raw;
  raw.reserve(kept.size());
  for (const size_t i : kept) {
    TimedPoint p;
    p.point = config_.T_imu_lidar * scan.points[i];
    // Points are registered between the previous knot and this one; a time outside (clock
    // jitter of the driver) is clamped rather than extrapolated.
    p.time = std::clamp(Seconds(scan.times_ns[i]), t_prev, prepared.t_end);
    raw.push_back(p);
  }
  prepared.points = frontend_.Preprocess(raw);
  prepared.keypoints = frontend_.Keypoints(prepared.points);
  SortByTime(&prepared.points);
  SortByTime(&prepared.keypoints);

  ScanResult result;
  result.ms_preprocess = MsSince(start);
  result.t_ns = scan.end_ns;
  result.keypoints = static_cast<int>(prepared.keypoints.size());
  try {
    if (!initialised_) {
      std::string message;
      if (uses_imu() && !InitialiseGravity(prepared.t_end, &message)) {
        result.status = ScanStatus::kFailed;
        result.message = message;
      } else {
        Initialise(prepared, &result);
        initialised_ = true;
        last_scan_end_ns_ = scan.end_ns;
        if (result.status == ScanStatus::kOk) result.status = ScanStatus::kInitialising;
      }
    } else {
      Process(prepared, &result);
      last_scan_end_ns_ = scan.end_ns;
    }
  } catch (const std::exception& e) {
    result.status = ScanStatus::kFailed;
    result.message = e.what();
  }
  if (!initialised_) last_scan_end_ns_ = scan.end_ns;
  TrimImu(Seconds(last_scan_end_ns_) - 0.5);
  result.milliseconds = MsSince(start);
  result.cpu_ms = ThreadCpuMs() - cpu_start;
  results_.push_back(result);
  return result;
}

std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config) {
  if (config.method == LioMethod::kImuInput) return std::make_unique<ImuInputLio>(config);
  return std::make_unique<SingerLio>(config);
}

}  // namespace ctlio::lio
