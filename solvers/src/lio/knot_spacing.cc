#include "ctlio/solvers/lio/knot_spacing.h"

#include <algorithm>
#include <cmath>

namespace ctlio::lio {

double LineResidualRms(const std::vector<double>& t, const std::vector<Vec3>& x) {
  const size_t n = std::min(t.size(), x.size());
  if (n < 3) return 0.0;
  const auto [t_min, t_max] = std::minmax_element(t.begin(), t.begin() + n);
  if (!(*t_max > *t_min)) return 0.0;  // no spread in time: no line to measure against
  // Centred sums: the line through the means, slope Σ(t−t̄)(x−x̄)/Σ(t−t̄)² per axis.
  double t_mean = 0.0;
  Vec3 x_mean = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) {
    t_mean += t[i];
    x_mean += x[i];
  }
  t_mean /= static_cast<double>(n);
  x_mean /= static_cast<double>(n);
  double stt = 0.0;
  Vec3 stx = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double dt = t[i] - t_mean;
    stt += dt * dt;
    stx += dt * (x[i] - x_mean);
  }
  const Vec3 slope = stx / stt;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sum += (x[i] - x_mean - slope * (t[i] - t_mean)).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(n));
}

namespace {

// The fewest K ≥ 1 with r / K² ≤ threshold (the residual of a line over 1/K of the interval).
int KnotsFor(double residual, double threshold) {
  if (!(threshold > 0.0) || !(residual > threshold)) return 1;
  const double k = std::ceil(std::sqrt(residual / threshold) - 1e-12);
  return k > 1000.0 ? 1000 : std::max(1, static_cast<int>(k));
}

}  // namespace

int KnotsForSweep(const AdaptiveKnotOptions& options, int knots_per_scan,
                  const std::vector<double>& t, const std::vector<Vec3>& gyro,
                  const std::vector<Vec3>& accel) {
  if (!options.enabled(knots_per_scan)) return knots_per_scan;
  int k = knots_per_scan;
  if (options.gyro_curvature > 0.0) {
    k = std::max(k, KnotsFor(LineResidualRms(t, gyro), options.gyro_curvature));
  }
  if (options.accel_curvature > 0.0) {
    k = std::max(k, KnotsFor(LineResidualRms(t, accel), options.accel_curvature));
  }
  return std::min(k, options.max_knots_per_scan);
}

}  // namespace ctlio::lio
