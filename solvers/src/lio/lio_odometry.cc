#include "ctlio/solvers/lio/lio_odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ctlio/factors/imu/gravity_initialization.h"
#include "ctlio/solvers/lio/imu_input_lio.h"
#include "ctlio/solvers/lio/singer_lio.h"

namespace ctlio::lio {

LioOdometry::LioOdometry(const OdometryConfig& config)
    : frontend_(config.frontend), config_(config) {
  config_.Validate();
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
  std::vector<TimedPoint> raw;
  raw.reserve(scan.points.size());
  for (size_t i = 0; i < scan.points.size(); ++i) {
    TimedPoint p;
    p.point = config_.T_imu_lidar * scan.points[i];
    // Points are registered between the previous knot and this one; a time outside (clock
    // jitter of the driver) is clamped rather than extrapolated.
    p.time = std::clamp(Seconds(scan.times_ns[i]), t_prev, prepared.t_end);
    raw.push_back(p);
  }
  prepared.points = frontend_.Preprocess(raw);
  prepared.keypoints = frontend_.Keypoints(prepared.points);
  // Time order groups the points of one firing, whose interpolated pose the pipelines share.
  const auto by_time = [](const TimedPoint& a, const TimedPoint& b) { return a.time < b.time; };
  std::stable_sort(prepared.points.begin(), prepared.points.end(), by_time);
  std::stable_sort(prepared.keypoints.begin(), prepared.keypoints.end(), by_time);

  ScanResult result;
  result.ms_preprocess =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
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
  result.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  results_.push_back(result);
  return result;
}

std::unique_ptr<LioOdometry> MakeLioOdometry(const OdometryConfig& config) {
  if (config.method == LioMethod::kImuInput) return std::make_unique<ImuInputLio>(config);
  return std::make_unique<SingerLio>(config);
}

}  // namespace ctlio::lio
