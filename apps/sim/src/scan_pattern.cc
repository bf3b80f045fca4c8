#include "ctlio/sim/scan_pattern.h"

#include <cmath>

namespace ctlio::sim {

Vec3 PatternDirection(const ScanPattern& p, int line, int lines, double t) {
  constexpr double kTwoPi = 2.0 * M_PI, kDeg = M_PI / 180.0;
  const double phase = kTwoPi * double(line) / double(lines);
  double az = 0.0, el = 0.0;
  if (p.kind == PatternKind::kMid360) {
    const double c = 0.5 * (p.max_elevation_deg + p.min_elevation_deg);
    const double h = 0.5 * (p.max_elevation_deg - p.min_elevation_deg);
    el = (c + h * (p.weight * std::sin(kTwoPi * p.f1_hz * t + phase) +
                   (1.0 - p.weight) * std::sin(kTwoPi * p.f2_hz * t))) *
         kDeg;
    az = kTwoPi * p.azimuth_hz * t + phase;
  } else {  // kRosette
    const double a = kTwoPi * p.f1_hz * t, b = kTwoPi * p.f2_hz * t + phase;
    az = p.half_azimuth_deg * kDeg * 0.5 * (std::cos(a) + std::cos(b));
    el = p.half_elevation_deg * kDeg * 0.5 * (std::sin(a) + std::sin(b));
  }
  const double ce = std::cos(el);
  return Vec3(ce * std::cos(az), ce * std::sin(az), std::sin(el));
}

}  // namespace ctlio::sim
