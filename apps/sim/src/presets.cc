#include "ctlio/sim/presets.h"

#include <stdexcept>

#include "ctlio/io/newer_college.h"
#include "ctlio/sim/sensor_effects.h"
#include "ctlio/sim/sensor_models.h"

namespace ctlio::sim {

Preset ParsePreset(const std::string& name) {
  if (name.empty() || name == "none") return Preset::kNone;
  if (name == "newer_college") return Preset::kNewerCollege;
  if (name == "kitti") return Preset::kKitti;
  throw std::runtime_error("unknown preset '" + name + "' (none, newer_college, kitti)");
}

const char* PresetName(Preset preset) {
  switch (preset) {
    case Preset::kNewerCollege:
      return "newer_college";
    case Preset::kKitti:
      return "kitti";
    default:
      return "none";
  }
}

Regime PresetRegime(Preset preset) {
  switch (preset) {
    case Preset::kNewerCollege:
      return Regime::kWalking;
    case Preset::kKitti:
      return Regime::kVehicle;
    default:
      return Regime::kFast;
  }
}

WorldKind PresetWorld(Preset preset) {
  switch (preset) {
    case Preset::kNewerCollege:
      return WorldKind::kQuad;
    case Preset::kKitti:
      return WorldKind::kTown;
    default:
      return WorldKind::kBox;
  }
}

double PresetDuration(Preset preset) {
  switch (preset) {
    case Preset::kNewerCollege:
      return 120.0;
    case Preset::kKitti:
      return 60.0;
    default:
      return 20.0;
  }
}

void ApplyKittiSensors(SimConfig* config) {
  LidarConfig& L = config->lidar;
  L.beams = 64;
  L.min_elevation_deg = -24.8;
  L.max_elevation_deg = 2.0;
  L.firings_per_revolution = 2000;
  L.rate_hz = 10.0;
  L.range_noise = 0.02;
  L.range_noise_per_m = 0.0;
  L.min_range = 2.0;
  L.max_range = 120.0;
  ImuConfig& I = config->imu;
  I.rate_hz = 100.0;
  I.accel_noise = 0.02;
  I.gyro_noise = 0.002;
  I.accel_bias_walk = 1e-4;
  I.gyro_bias_walk = 1e-5;
  I.body_centric = false;
}

void ApplyNewerCollegeSensors(SimConfig* config) {
  LidarConfig& L = config->lidar;
  L.beams = 64;
  L.min_elevation_deg = -16.6;
  L.max_elevation_deg = 16.6;
  L.firings_per_revolution = 1024;
  L.rate_hz = 10.0;
  L.range_noise = 0.015;
  L.range_noise_per_m = 0.0005;
  L.min_range = 0.8;
  L.max_range = 120.0;
  ImuConfig& I = config->imu;
  I.rate_hz = 100.0;
  I.accel_noise = 0.05;
  I.gyro_noise = 0.005;
  I.accel_bias_walk = 1e-3;
  I.gyro_bias_walk = 1e-4;
  I.body_centric = false;
  I.gravity = 9.81599;
  config->imu_from_lidar = io::NewerCollegeImuFromLidar();
}

std::string PresetSensorEffects(Preset preset, const SimOverrides& o) {
  const std::string effects = o.sensor_effects.value_or("auto");
  if (effects != "auto") return effects;
  // A sensor model in one of the realistic worlds (quad, town, office: the worlds measured
  // against real sweeps, docs/experiments/worlds-geometry.md) gets its unit's effects too; the
  // older worlds and Table II's box stay ideal, bit for bit.
  const WorldKind world = o.world.value_or(PresetWorld(preset));
  const bool realistic =
      world == WorldKind::kQuad || world == WorldKind::kTown || world == WorldKind::kOffice;
  if (preset == Preset::kNone && !(o.sensor && realistic)) return "off";
  if (o.sensor) return FindSensorModel(*o.sensor).effects_family;
  return preset == Preset::kKitti ? "hdl64" : "ouster";
}

SimConfig PresetConfig(Preset preset, int index, uint64_t seed, const SimOverrides& o) {
  SimConfig c = ExperimentConfig(o.regime.value_or(PresetRegime(preset)), index, seed,
                                 o.world.value_or(PresetWorld(preset)));
  c.duration_s = PresetDuration(preset);
  if (preset == Preset::kNewerCollege) ApplyNewerCollegeSensors(&c);
  if (preset == Preset::kKitti) ApplyKittiSensors(&c);
  if (o.sensor) {
    const SensorModel& m = FindSensorModel(*o.sensor);
    ApplySensorModel(m, &c);
    if (o.beams && *o.beams != m.lidar.beams &&
        (!m.lidar.elevations_deg.empty() || m.lidar.pattern.kind != PatternKind::kSpinning)) {
      throw std::runtime_error("--beams " + std::to_string(*o.beams) +
                               " does not apply to sensor " + m.name + " (its " +
                               std::to_string(m.lidar.beams) + " beams are the datasheet's)");
    }
  }
  const std::string effects = PresetSensorEffects(preset, o);
  if (effects != "off") {
    // One unit per experiment seed (never 0: 0 means "the noise seed" to the simulator).
    const uint64_t unit = (seed ^ 0x5E450C7EF1A3B2D9ULL) | 1ULL;
    ApplySensorEffects(SensorEffectsOf(effects), unit, &c.lidar);
  }
  if (o.duration_s) c.duration_s = *o.duration_s;
  if (o.beams) c.lidar.beams = *o.beams;
  if (o.firing_decimation) c.lidar.firing_decimation = *o.firing_decimation;
  if (o.lidar_rate_hz) {
    if (!(*o.lidar_rate_hz > 0.0 && *o.lidar_rate_hz <= 100.0)) {
      throw std::runtime_error("lidar rate " + std::to_string(*o.lidar_rate_hz) +
                               " Hz: must be in (0, 100]");
    }
    c.lidar.rate_hz = *o.lidar_rate_hz;
  }
  if (o.range_noise_per_m) c.lidar.range_noise_per_m = *o.range_noise_per_m;
  if (o.body_centric) c.imu.body_centric = *o.body_centric;
  if (o.accel_bias_walk) c.imu.accel_bias_walk = *o.accel_bias_walk;
  if (o.gyro_bias_walk) c.imu.gyro_bias_walk = *o.gyro_bias_walk;
  if (o.newer_college_extrinsic) {
    c.imu_from_lidar = *o.newer_college_extrinsic ? io::NewerCollegeImuFromLidar() : SE3();
  }
  return c;
}

}  // namespace ctlio::sim
