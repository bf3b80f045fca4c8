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

bool ScanWithoutImu::RejectsCorrection(bool uses_imu, double correction, double limit,
                                       ScanResult* result) const {
  if (!active() || !uses_imu || limit <= 0.0 || !(correction > limit)) return false;
  if (result->status == ScanStatus::kFailed) return false;  // already rejected as a divergence
  std::ostringstream m;
  m << "registration moved the pose " << correction << " m from the prediction (limit " << limit
    << " m, lidar_frontend.max_correction_without_imu) with no IMU sample in the scan: rejected, "
       "the prediction is kept and the scan's points stay out of the map";
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
