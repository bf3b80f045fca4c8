#include "lio/accel_reference.h"

#include <algorithm>
#include <cstdio>

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
      frames_(config.ImuPose(0)),
      max_scans_(max_scans) {}

AccelReference::~AccelReference() = default;

void AccelReference::AddImu(const lio::ImuSample& sample) {
  if (!Active()) return;
  odometry_->AddImu(sample);
  frames_.AddImu(sample);
}

void AccelReference::AddScan(const lio::LidarScan& scan) {
  if (!Active()) return;
  ++scans_;
  const lio::ScanResult r = odometry_->AddScan(scan);
  if (r.status == lio::ScanStatus::kOk) {
    frames_.AddPose(r.t_ns, r.T_mr);
  } else {
    frames_.Break();
  }
  // The estimator's memory is not needed past the stretch.
  if (!Active()) odometry_.reset();
}

}  // namespace ctlio::lioapp
