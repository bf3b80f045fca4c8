#include "ctlio/solvers/lio/scan_status.h"

#include <sstream>
#include <string>

namespace ctlio::lio {

bool CheckPlausibleJump(double jump, bool finite, double limit, ScanResult* result) {
  if (finite && jump <= limit) return true;
  std::ostringstream m;
  m << "pose jumped " << jump << " m in one scan (limit " << limit << " m): estimate diverged";
  result->status = ScanStatus::kFailed;
  result->message = m.str();
  return false;
}

void MarkTooFewAssociations(int min_associations, bool uses_imu, ScanResult* result) {
  if (result->status != ScanStatus::kOk) return;
  result->status = ScanStatus::kDegenerate;
  result->message = "only " + std::to_string(result->associations) + " plane associations (need " +
                    std::to_string(min_associations) +
                    "): lidar term dropped for this scan, the prior" +
                    (uses_imu ? " and the IMU carry" : " carries") + " the state";
}

void MarkDegenerateDirections(ScanResult* result) {
  if (result->status != ScanStatus::kOk) return;
  result->status = ScanStatus::kDegenerate;
  result->message = std::to_string(result->degeneracy.num_degenerate()) +
                    " degenerate direction(s) of the lidar term (least constrained " +
                    result->degeneracy.DirectionString() + " in the body frame): no IMU to carry " +
                    (result->degeneracy.remapped
                         ? "them, the constant-velocity prediction is kept along them (solution "
                           "remapping)"
                         : "them (degeneracy.remap off: the estimate along them is the lidar's)");
}

}  // namespace ctlio::lio
