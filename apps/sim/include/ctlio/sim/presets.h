// Simulator presets: a recording shaped like a real dataset (docs/user-guide/simulator.md).
//
// `newer_college` (Newer College Dataset 2020, SPEC §6): a handheld Ouster OS1-64 (Gen1) with
// its internal IMU, carried by a walking person through the park world.
//   Lidar (OS1 datasheet, Gen1): 64 beams evenly spaced over +16.6° … −16.6° (33.2°), 1024
//   columns (firings per revolution), 10 Hz, range 0.8–120 m; range repeatability 1σ is 1.5 cm
//   at high SNR, 3 cm at SNR 100 and 10 cm at SNR 12, modelled as σ(r) = 1.5 cm + 0.05 %·r
//   (2.5 cm at 20 m, 7.5 cm at 120 m).
//   IMU: 100 Hz, σ_a = 0.05 m/s² and σ_g = 0.005 rad/s per sample (the per-sample σ that
//   data/newer_college_lio.yaml assumes for the OS1's IMU), bias random walk 1e-3 m/s²/√s and
//   1e-4 rad/s/√s (a consumer MEMS IMU), initial biases 0.05, g = 9.81599 m/s² (SPEC §4).
//   Extrinsic: the published T_imu_lidar (rotation diag(−1, −1, 1), translation (−0.006253,
//   0.011775, 0.028535) m; SPEC §6). Motion: the walking regime (≈1.4 m/s with gait and head
//   turns) in the college quad (`quad`, worlds.h: buildings round a lawn, an arch, a park with
//   trees); 120 s. (Until the quad existed the preset walked in `park`; --world park gives that.)
//
// `kitti` (KITTI odometry, Velodyne HDL-64E on a car): 64 beams evenly spaced over +2° … −24.8°
//   (the real lasers are in two blocks, ≈1/3° and ≈1/2° apart: uniform spacing is the
//   approximation here), 2000 firings per revolution (≈0.18°, ~120 k returns a sweep as KITTI's
//   scans have), 10 Hz, range 2–120 m, σ = 2 cm (datasheet: < 2 cm); a car-grade IMU at 100 Hz
//   (σ_a = 0.02 m/s², σ_g = 0.002 rad/s, small bias walks), identity extrinsic. Motion: the
//   vehicle regime (8–14 m/s) in the town street (`town`); 60 s.
// The exact specific force is generated (the real accelerometer measures it).
#pragma once

#include <optional>
#include <string>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {

enum class Preset { kNone, kNewerCollege, kKitti };
// "" or "none" → kNone, "newer_college" → kNewerCollege, "kitti" → kKitti; throws
// std::runtime_error otherwise.
Preset ParsePreset(const std::string& name);
const char* PresetName(Preset preset);

// Settings given explicitly (e.g. on a command line): they win over the preset's.
struct SimOverrides {
  std::optional<Regime> regime;
  std::optional<WorldKind> world;
  std::optional<double> duration_s;
  std::optional<int> beams;
  std::optional<int> firing_decimation;
  std::optional<double> lidar_rate_hz;  // revolutions (scans) per second, in (0, 100]
  std::optional<double> range_noise_per_m;
  std::optional<bool> body_centric;
  std::optional<double> accel_bias_walk;  // m/s²/√s
  std::optional<double> gyro_bias_walk;   // rad/s/√s
  std::optional<bool> newer_college_extrinsic;
  // A sensor model (sensor_models.h) replacing the preset's lidar, IMU and extrinsic; the other
  // overrides apply on top of it (`beams` only to a sensor without a datasheet beam table).
  std::optional<std::string> sensor;
  // The unit's sensor effects (sensor_effects.h): "off", or a family (ouster, hdl64, ...); unset:
  // the preset's (newer_college: ouster, kitti: hdl64, or the --sensor model's family); without
  // a preset, the sensor model's family in the realistic worlds (quad, town, office), else none.
  std::optional<std::string> sensor_effects;
};

// The sensor-effects family PresetConfig applies ("off" or a family), `overrides.sensor_effects`
// resolved when unset or "auto" (see SimOverrides::sensor_effects).
std::string PresetSensorEffects(Preset preset, const SimOverrides& overrides);

// The preset's regime, world and duration (kNone: fast, box, 20 s: the Table II simulator).
Regime PresetRegime(Preset preset);
WorldKind PresetWorld(Preset preset);
double PresetDuration(Preset preset);

// Sequence `index` of the preset: ExperimentConfig(regime, index, seed, world) with the preset's
// sensors, IMU, extrinsic and duration, then the sensor model and every other given override.
// The sensor effects' unit is drawn from `seed` alone: every index shares one unit.
SimConfig PresetConfig(Preset preset, int index, uint64_t seed = kExperimentSeed,
                       const SimOverrides& overrides = {});

// The preset's sensors, IMU and extrinsic applied to `config` (motion, world and duration kept).
void ApplyNewerCollegeSensors(SimConfig* config);
void ApplyKittiSensors(SimConfig* config);

}  // namespace ctlio::sim
