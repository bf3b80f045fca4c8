#include "ctlio/solvers/lio/scan_without_imu.h"

#include <algorithm>

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

bool ScanWithoutImu::Restore(const RegistrationSummary& registered, SlidingWindow* window) const {
  if (!active()) return false;
  for (const ceres::ResidualBlockId id : registered.lidar_blocks) window->RemoveResidualBlock(id);
  for (const auto& [id, value] : start_) {
    std::copy(value.data(), value.data() + value.size(), window->State(id));
  }
  return true;
}

}  // namespace ctlio::lio
