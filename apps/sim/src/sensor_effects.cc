#include "ctlio/sim/sensor_effects.h"

#include <stdexcept>

namespace ctlio::sim {

bool SensorEffects::Any() const {
  return elevation_error_deg > 0 || azimuth_error_deg > 0 || range_offset_sigma > 0 ||
         beam_divergence_rad > 0 || mixed_pixel_probability > 0 || grazing_dropout_start_deg < 90.0;
}

SensorEffects SensorEffectsOf(const std::string& family) {
  // Common to every family (tuned on the presets, world seeds 11–13): half of the depth-edge
  // returns mixed, losses from 85° incidence on, an effective divergence of 2 mrad in the
  // footprint model (Ouster's datasheet: 3.1 mrad FWHM; the echo's peak detection weights the
  // spot's centre).
  SensorEffects e;
  e.beam_divergence_rad = 2.0e-3;
  e.mixed_pixel_probability = 0.5;
  e.mixed_pixel_min_gap = 0.3;
  e.grazing_dropout_start_deg = 85.0;
  if (family == "ouster" || family == "velodyne" || family == "hesai") {
    e.elevation_error_deg = 0.04;
    e.azimuth_error_deg = 0.04;
    e.range_offset_sigma = family == "velodyne" ? 0.015 : 0.01;
  } else if (family == "hdl64") {
    // KITTI's HDL-64E: 64 lasers in two blocks, the residuals of its calibration table larger
    // than the smaller heads' (per-laser elevation corrections of ≈ 0.2° are reported for
    // KITTI's scans).
    e.elevation_error_deg = 0.1;
    e.azimuth_error_deg = 0.1;
    e.range_offset_sigma = 0.02;
  } else if (family != "livox") {  // livox: no beams, no per-beam errors
    throw std::runtime_error("unknown sensor-effect family '" + family +
                             "' (ouster, hdl64, velodyne, hesai, livox)");
  }
  return e;
}

void ApplySensorEffects(const SensorEffects& e, uint64_t unit_seed, LidarConfig* L) {
  if (unit_seed == 0) throw std::runtime_error("ApplySensorEffects: unit seed must be non-zero");
  L->unit_seed = unit_seed;
  L->effects = e;
}

}  // namespace ctlio::sim
