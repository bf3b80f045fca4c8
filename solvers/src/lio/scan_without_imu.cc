#include "ctlio/solvers/lio/scan_without_imu.h"

#include <algorithm>
#include <sstream>

namespace ctlio::lio {

bool ScanWithoutImu::Applies(LioMethod method, const ScanResult& result) {
  return method != LioMethod::kImuInput && result.imu_residuals == 0;
}

void ScanWithoutImu::Begin(bool applies, const std::vector<StateId>& keys,
                           const SlidingWindow& window) {
  start_.clear();
  if (!applies) return;
  for (const StateId id : keys) start_.emplace_back(id, window.Vector(id));
}

bool ScanWithoutImu::RejectsCorrection(bool uses_imu, const LidarFrontendOptions& options,
                                       ScanResult* result) const {
  if (!active() || !uses_imu) return false;
  if (result->status == ScanStatus::kFailed) return false;  // already rejected as a divergence
  const double limit_m = options.max_correction_without_imu;
  const double limit_rad = options.max_rotation_correction_without_imu;
  // NaN corrections are rejected: !(x <= limit).
  const bool moved = limit_m > 0.0 && !(result->correction_m <= limit_m);
  const bool turned = limit_rad > 0.0 && !(result->correction_rad <= limit_rad);
  if (!moved && !turned) return false;
  std::ostringstream m;
  if (moved) {
    m << "registration moved the pose " << result->correction_m << " m from the prediction (limit "
      << limit_m << " m, lidar_frontend.max_correction_without_imu)";
  } else {
    m << "registration turned the pose " << result->correction_rad
      << " rad from the prediction (limit " << limit_rad
      << " rad, lidar_frontend.max_rotation_correction_without_imu)";
  }
  m << " with no IMU sample in the scan: rejected, the prediction is kept and the scan's points "
       "stay out of the map";
  if (!result->message.empty()) m << "; " << result->message;
  result->status = ScanStatus::kDegenerate;
  result->message = m.str();
  return true;
}

bool ScanWithoutImu::Restore(const RegistrationSummary& registered, SlidingWindow* window) const {
  if (!active()) return false;
  for (const ceres::ResidualBlockId id : registered.lidar_blocks) window->RemoveResidualBlock(id);
  for (const auto& [id, value] : start_) {
    std::copy(value.data(), value.data() + value.size(), window->State(id));
  }
  return true;
}

}  // namespace ctlio::lio
