// Non-repetitive scan patterns of the Livox lidars (sensor_models.h). Livox does not publish its
// scan heads' trajectories, so these are surrogates with the datasheets' field of view, point rate
// and the one property that matters to an odometry: the pattern never repeats, so the coverage of
// the field of view grows with integration time and consecutive 10 Hz frames sample different
// directions.
//
// A pattern scans `lines` lasers fired together (the sim's `beams`; Mid-360: 4, Avia: 6), each at
// points_per_second / lines, the firing times on the simulator's firing grid. The direction of
// line l at time t [s since the sequence start, continuous across frames]:
//
// * kMid360 (360° × [min_el, max_el]): the azimuth turns at `azimuth_hz` (lines offset by 360°/L)
//   and the elevation is the sum of two rotations projected on one axis,
//     el(t) = c + h·(w·sin(2π f₁ t + 2πl/L) + (1 − w)·sin(2π f₂ t)),  c ± h = max/min_el,
//   with f₁/f₂ and f₁/azimuth_hz irrational (golden-ratio based), so no (azimuth, elevation) pair
//   recurs.
// * kRosette (Avia; a Risley prism pair): two counter-rotating deflections of equal size,
//     δ(t) = ½[cos(2π f₁ t) + cos(2π f₂ t + 2πl/L), sin(2π f₁ t) + sin(2π f₂ t + 2πl/L)],
//   f₂ < 0 (counter-rotation) with |f₂/f₁| irrational: the rosette's petals pass through the centre
//   and precess, never closing. Azimuth = half_azimuth·δₓ, elevation = half_elevation·δᵧ around the
//   forward x axis (|δ| ≤ 1: the field of view is the ellipse inside 2·half_azimuth ×
//   2·half_elevation).
#pragma once

#include "ctlio/manifolds/types.h"

namespace ctlio::sim {

enum class PatternKind { kSpinning, kMid360, kRosette };

struct ScanPattern {
  PatternKind kind = PatternKind::kSpinning;  // kSpinning: the beams × firings grid of LidarConfig
  double f1_hz = 0.0, f2_hz = 0.0;            // the two rotations
  double azimuth_hz = 0.0;                    // kMid360: azimuth turns per second
  double weight = 0.5;                        // kMid360: w
  double min_elevation_deg = 0.0, max_elevation_deg = 0.0;  // kMid360
  double half_azimuth_deg = 0.0, half_elevation_deg = 0.0;  // kRosette
};

// Unit direction (lidar frame: x forward, z up) of line `line` of `lines` at time t [s].
Vec3 PatternDirection(const ScanPattern& pattern, int line, int lines, double t);

}  // namespace ctlio::sim
