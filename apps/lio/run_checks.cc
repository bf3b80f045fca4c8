#include "lio/run_checks.h"

#include <algorithm>
#include <cstdio>

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

}  // namespace ctlio::lioapp
