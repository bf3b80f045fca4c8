#include "lio/accel_reference.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace ctlio::lioapp {

std::string RelabellingWarning(const FrameConsistency& reference, int scans,
                               const RelabellingOptions& options) {
  if (reference.windows == 0 || reference.best_relabelling.empty()) return "";
  if (reference.identity_rms < options.min_gain * reference.best_relabelling_rms ||
      reference.best_relabelling_rms > options.max_over_free * reference.free_rms) {
    return "";
  }
  char text[900];
  std::snprintf(text, sizeof(text),
                "accelerometer axes look swapped/flipped: best relabelling true (x, y, z) = "
                "reading %s explains the accelerations of a lidar + gyro reference trajectory "
                "(first %d scans, no accelerometer in it) with residual RMS %.3g m/s^2 against "
                "%.3g as read (%.2fx; threshold %.2fx) and %.3g for a free 3x3 map: the "
                "accelerometer's columns are likely relabelled or sign-flipped (check the IMU "
                "driver's axis convention), or the IMU's mounting rotation is wrong",
                reference.best_relabelling.c_str(), scans, reference.best_relabelling_rms,
                reference.identity_rms,
                reference.identity_rms / std::max(reference.best_relabelling_rms, 1e-12),
                options.min_gain, reference.free_rms);
  return text;
}

std::string DisagreementWarning(const ReferenceDisagreement& d, int scans,
                                const DisagreementOptions& options) {
  if (options.max_fraction <= 0.0 || d.pairs < options.min_pairs || d.path_m < options.min_path_m ||
      d.rms_m <= options.max_fraction * d.path_m) {
    return "";
  }
  char text[900];
  std::snprintf(text, sizeof(text),
                "the estimate departs from a lidar + gyro reference (no accelerometer in it) by "
                "%.3g m RMS (max %.3g m) over the first %d scans (%.1f %% of its %.3g m path; "
                "threshold %.1f %%): an IMU defect (accelerometer axes, signs or units, the "
                "extrinsic) or a scene the lidar does not constrain",
                d.rms_m, d.max_m, scans, 100.0 * d.rms_m / d.path_m, d.path_m,
                100.0 * options.max_fraction);
  return text;
}

std::string ReferenceRanOff(const ReferenceDisagreement& d, const ReferenceTrustOptions& options) {
  if (d.pairs == 0 || d.extent_m < options.min_extent_m ||
      !(d.extent_m > options.max_extent_ratio * d.estimate_extent_m)) {
    return "";
  }
  char text[600];
  std::snprintf(text, sizeof(text),
                "the lidar + gyro reference went %.3g m from its start where the estimate went "
                "%.3g m (%.2fx; more than %.2fx): the reference ran off on its own (no "
                "accelerometer in it; a sparse lidar), so neither the relabelling nor the "
                "departure is judged",
                d.extent_m, d.estimate_extent_m, d.extent_m / std::max(d.estimate_extent_m, 1e-12),
                options.max_extent_ratio);
  return text;
}

FrameConsistencyCheck ImuFrameCheck(const lio::OdometryConfig& config) {
  return FrameConsistencyCheck(config.ImuPose(0), 0, {}, config.calibration.TimeOffset(0));
}

namespace {
lio::OdometryConfig ReferenceConfig(lio::OdometryConfig c) {
  c.method = lio::LioMethod::kLidarGyro;
  c.calibration.estimate_extrinsic = false;
  c.calibration.estimate_time_offset = false;
  c.pose_covariance = false;
  return c;
}
}  // namespace

AccelReference::AccelReference(const lio::OdometryConfig& config, size_t max_scans)
    : odometry_(std::make_unique<lio::LioOdometry>(ReferenceConfig(config))),
      frames_(ImuFrameCheck(config)),
      max_scans_(max_scans) {}

AccelReference::~AccelReference() = default;

void AccelReference::AddImu(const lio::ImuSample& sample) {
  if (!Active()) return;
  odometry_->AddImu(sample);
  frames_.AddImu(sample);
}

void AccelReference::AddScan(const lio::LidarScan& scan) {
  took_last_scan_ = Active();
  if (!took_last_scan_) return;
  ++scans_;
  const lio::ScanResult r = odometry_->AddScan(scan);
  if (r.status == lio::ScanStatus::kOk) {
    frames_.AddPose(r.t_ns, r.T_mr);
    reference_poses_.emplace_back(r.t_ns, r.T_mr);
  } else {
    frames_.Break();
  }
  // The estimator's memory is not needed past the stretch.
  if (!Active()) odometry_.reset();
}

void AccelReference::AddEstimate(int64_t t_ns, const SE3& T_mr) {
  if (!took_last_scan_ || !T_mr.translation().allFinite()) return;
  estimate_poses_.emplace_back(t_ns, T_mr);
}

ReferenceDisagreement AccelReference::Disagreement() const {
  ReferenceDisagreement d;
  std::map<int64_t, const SE3*> estimate;
  for (const auto& [t, T] : estimate_poses_) estimate[t] = &T;
  const SE3* ref0 = nullptr;
  const SE3* est0 = nullptr;
  Vec3 previous = Vec3::Zero();
  Vec3 previous_estimate = Vec3::Zero();
  double sum_sq = 0.0;
  for (const auto& [t, T] : reference_poses_) {
    const auto it = estimate.find(t);
    if (it == estimate.end() || !T.translation().allFinite()) continue;
    if (ref0 == nullptr) {
      ref0 = &T;
      est0 = it->second;
    }
    const Vec3 p_ref = (ref0->Inverse() * T).translation();
    const Vec3 p_est = (est0->Inverse() * *it->second).translation();
    const double e = (p_est - p_ref).norm();
    if (d.pairs > 0) {
      d.path_m += (p_ref - previous).norm();
      d.estimate_path_m += (p_est - previous_estimate).norm();
    }
    previous = p_ref;
    previous_estimate = p_est;
    d.extent_m = std::max(d.extent_m, p_ref.norm());
    d.estimate_extent_m = std::max(d.estimate_extent_m, p_est.norm());
    sum_sq += e * e;
    d.max_m = std::max(d.max_m, e);
    ++d.pairs;
  }
  if (d.pairs > 0) d.rms_m = std::sqrt(sum_sq / d.pairs);
  return d;
}

}  // namespace ctlio::lioapp
