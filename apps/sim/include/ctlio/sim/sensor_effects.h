// Effects of a real lidar unit that make its sweeps less ideal than the world's geometry: fixed
// per-beam angle and range errors (an intrinsic calibration's residuals, the same in every
// sequence of one unit), the footprint's depth spread at oblique incidence, mixed pixels at depth
// edges and dropouts at grazing incidence (LidarConfig documents each model). The presets
// (presets.h) and the sensor models (sensor_models.h) carry their sensor's effects; the default
// simulator (Table II's box) has none unless they are asked for.
//
// The values are of the sensor class, not of a measured unit: datasheet beam divergence; angle
// and range residuals of the order reported for factory-calibrated spinning lidars (Velodyne
// HDL-64E: per-laser corrections of tenths of a degree and centimetres, the residuals after the
// factory table about a tenth of that and more for the 64-laser head; Ouster: tighter); the rest
// set so that the presets' sweeps match the real ones in the geometry statistic
// (docs/experiments/worlds-geometry.md), tuned on world seeds 11–13 only.
#pragma once

#include <cstdint>
#include <string>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {

// SensorEffects: lidar_inertial_sim.h (a part of LidarConfig).

// The effects of a sensor family: "ouster" (OS0/OS1), "hdl64" (KITTI's HDL-64E), "velodyne"
// (VLP-16, HDL-32E), "hesai" (Pandar XT-32), "livox" (no beams: footprint, mixed pixels and
// grazing dropouts only). Throws std::runtime_error naming the families otherwise.
SensorEffects SensorEffectsOf(const std::string& family);

// The effects applied to `lidar` (replacing its `effects`), the unit's fixed errors drawn from
// `unit_seed` (non-zero; the same unit in every sequence that passes it).
void ApplySensorEffects(const SensorEffects& effects, uint64_t unit_seed, LidarConfig* lidar);

}  // namespace ctlio::sim
