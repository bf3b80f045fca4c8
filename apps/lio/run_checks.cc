#include "lio/run_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ctlio/solvers/lio/input_checks.h"

namespace ctlio::lioapp {

std::string UnregisteredRunReason(const std::vector<lio::ScanResult>& scans) {
  if (scans.size() < 2) {
    return "";
  }
  int degenerate = 0, failed = 0, suspect = 0;
  for (size_t i = 1; i < scans.size(); ++i) {
    switch (scans[i].status) {
      case lio::ScanStatus::kOk:
      case lio::ScanStatus::kImuGap:
        return "";
      case lio::ScanStatus::kDegenerate:
        ++degenerate;
        break;
      case lio::ScanStatus::kFailed:
        ++failed;
        break;
      case lio::ScanStatus::kSuspect:
        ++suspect;
        break;
      case lio::ScanStatus::kInitialising:
        break;
    }
  }
  return "no scan after the first was registered by the lidar (status ok or imu_gap): " +
         std::to_string(degenerate) + " degenerate, " + std::to_string(failed) + " failed, " +
         std::to_string(suspect) + " suspect of " + std::to_string(scans.size()) +
         " scans; the estimate is the motion prior's, not a measurement (empty scans, points "
         "outside lidar_frontend.min_range/max_range, or an unusable time field?)";
}

std::string DegenerateRunWarning(const std::vector<lio::ScanResult>& scans, double max_fraction) {
  if (scans.size() < 2) return "";
  size_t degenerate = 0, first = 0;
  for (size_t i = 1; i < scans.size(); ++i) {
    if (scans[i].status != lio::ScanStatus::kDegenerate) continue;
    if (degenerate++ == 0) first = i;
  }
  const size_t judged = scans.size() - 1;
  if (degenerate < 3 || double(degenerate) <= max_fraction * double(judged) ||
      degenerate == judged) {
    return "";
  }
  char text[600];
  std::snprintf(text, sizeof(text),
                "%zu of %zu scans degenerate (first: scan %zu at %.3f s): the lidar did not fix "
                "their pose, which there is the motion prior's and the IMU's dead reckoning; too "
                "few points or planes after subsampling (lidar_frontend.voxel_size, "
                "keypoint_voxel_size, max_keypoints), points outside min_range/max_range, a "
                "featureless scene, or registrations rejected in an IMU outage "
                "(lidar_frontend.max_correction_without_imu); scans.log has each scan's reason",
                degenerate, judged, first, 1e-9 * double(scans[first].t_ns));
  return text;
}

LidarGaps FindLidarGaps(const std::vector<int64_t>& scan_ends_ns, double factor) {
  LidarGaps g;
  if (scan_ends_ns.size() < 3) {
    return g;
  }
  std::vector<int64_t> dt;
  for (size_t i = 1; i < scan_ends_ns.size(); ++i) {
    dt.push_back(scan_ends_ns[i] - scan_ends_ns[i - 1]);
  }
  std::vector<int64_t> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const int64_t median = sorted[sorted.size() / 2];
  g.median_period_s = 1e-9 * static_cast<double>(median);
  if (median <= 0) {
    return g;
  }
  for (size_t i = 0; i < dt.size(); ++i) {
    if (static_cast<double>(dt[i]) <= factor * static_cast<double>(median)) {
      continue;
    }
    ++g.count;
    g.longest_s = std::max(g.longest_s, 1e-9 * static_cast<double>(dt[i]));
    if (g.first.empty()) {
      char text[200];
      std::snprintf(text, sizeof(text),
                    "gap of %.3f s between the scans ending at %.3f s and %.3f s (median scan "
                    "period %.3f s)",
                    1e-9 * static_cast<double>(dt[i]), 1e-9 * static_cast<double>(scan_ends_ns[i]),
                    1e-9 * static_cast<double>(scan_ends_ns[i + 1]), g.median_period_s);
      g.first = text;
    }
  }
  return g;
}

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::string Number(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof(text), format, v);
  return text;
}

}  // namespace

ImuConsistency CheckImuConsistency(const std::vector<lio::ScanResult>& scans,
                                   const lio::OdometryConfig& config,
                                   const ImuConsistencyOptions& options) {
  ImuConsistency c;
  std::vector<double> accel, gyro;
  for (size_t i = 1; i < scans.size(); ++i) {
    const lio::ScanResult& r = scans[i];
    if (r.status != lio::ScanStatus::kOk || r.accel_dof + r.gyro_dof == 0 ||
        scans[i - 1].status == lio::ScanStatus::kFailed ||
        !lio::PoseMoved(scans[i - 1].T_mr, r.T_mr, config.input)) {
      continue;
    }
    // A NaN χ² (a failed evaluation) is not evidence either way.
    if (r.accel_dof > 0 && std::isfinite(r.accel_chi2)) accel.push_back(r.accel_chi2 / r.accel_dof);
    if (r.gyro_dof > 0 && std::isfinite(r.gyro_chi2)) gyro.push_back(r.gyro_chi2 / r.gyro_dof);
  }
  c.moving_scans = static_cast<int>(std::max(accel.size(), gyro.size()));
  c.median_accel = Median(accel);
  c.median_gyro = Median(gyro);
  const bool baseline = config.method == lio::LioMethod::kImuInput;
  if (baseline) return c;
  std::string found;
  if (static_cast<int>(accel.size()) >= options.min_scans && c.median_accel > options.max_accel) {
    found = std::string("median chi2/dof ") + Number("%.3g", c.median_accel) + " of " +
            "the accelerometer terms over " + std::to_string(accel.size()) +
            " moving scans (threshold " + Number("%g", options.max_accel) +
            "; clean simulated runs 0.003 to 18): the accelerometer's sign (scale -1 reads like an "
            "upside-down IMU at rest and "
            "passes the gravity check), axes or units (g, not m/s^2) are likely wrong, or its "
            "noise setting " +
            "imu.accel_variance = " + Number("%g (m/s^2)^2", config.accel_variance) +
            " is too small";
  }
  if (static_cast<int>(gyro.size()) >= options.min_scans && c.median_gyro > options.max_gyro) {
    found += std::string(found.empty() ? "" : "; ") + "median chi2/dof " +
             Number("%.3g", c.median_gyro) + " of the gyro terms over " +
             std::to_string(gyro.size()) + " moving scans (threshold " +
             Number("%g", options.max_gyro) +
             "; clean simulated runs 0.003 to 0.14): the gyro's sign, axes or units (deg/s, not "
             "rad/s) are likely wrong, or "
             "imu.gyro_variance = " +
             Number("%g (rad/s)^2", config.gyro_variance) + " is too small";
  }
  if (!found.empty()) {
    c.warning = "the IMU disagrees with the motion the lidar fixed: " + found;
  }
  return c;
}

}  // namespace ctlio::lioapp
