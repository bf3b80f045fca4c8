#include "ctlio/solvers/lio/map_growth_covariance.h"

namespace ctlio::lio {

void MapGrowthCovariance::Registered(const Mat6& relative) {
  pending_ = 0.5 * (relative + relative.transpose());
  has_pending_ = true;
}

void MapGrowthCovariance::Inserted(size_t inserted, size_t map_points, double gain) {
  if (!has_pending_) return;
  has_pending_ = false;
  if (inserted == 0 || map_points == 0) return;
  const double beta = static_cast<double>(inserted) / static_cast<double>(map_points);
  map_ += gain * beta * beta * pending_;  // (1)
}

}  // namespace ctlio::lio
