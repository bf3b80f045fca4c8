// Lidar-inertial simulator of the paper's Table II experiment (SPEC §6): a spinning 128-beam
// lidar and a 200 Hz IMU moving inside a box room, with ground truth.
//
// Conventions (SPEC §1). The body (IMU) frame b moves with the body twist [v; ω] (IMU frame,
// translation first): Ṫ_wb = T_wb·[v; ω]^. The state velocity of SPEC §1 is ϖ = −[v; ω] (for
// T_rm = T_wb⁻¹). World frame w is gravity-aligned, z up, g_w = [0, 0, −g]. The lidar frame l is
// T_wl = T_wb·T_bl with T_bl = `imu_from_lidar`.
//
// IMU (SPEC §3):  gyro  = ω + b_g + n_g,
//                 accel = v̇ + ω×v − C_wbᵀ g_w + b_a + n_a   (exact specific force), or
//                 accel = v̇       − C_wbᵀ g_w + b_a + n_a   (`body_centric`: the paper's model).
// Several IMUs (SimConfig::extra_imus): IMU j sits at T_bi = body_from_imu (rotation C_bi, lever
// arm p) with its own rate, clock start, noise, biases and outages, and reads the rigid-body
// motion of its own origin (imu_mounting.h): ω_i = C_biᵀ ω, f_i = C_biᵀ(f_b + ω̇×p + ω×(ω×p)),
// f_b the body-origin specific force above.
// Motion (SPEC §6): stationary until `start_s`, then each of the six body-twist axes j follows
// amp_j·sin(2π f_j (t − start_s)), so the twist is continuous at start_s. Outside the box room
// (and for the walking and vehicle regimes everywhere) the motion is guided along the world's
// path (guided_motion.h): T_wb(t) = G(t)·P(t), G the guided pose, P the body-rate motion above
// integrated from the identity; then [v; ω] = Ad(P⁻¹)ξ_G + ξ_P and
// d/dt[v; ω] = Ad(P⁻¹)ξ̇_G − ξ_P^⋏·Ad(P⁻¹)ξ_G + ξ̇_P.
//
// Sensor realism (all off by default): range-dependent noise, lost returns (random dropout,
// grazing incidence, weak echoes), fixed per-beam angle and range errors of a unit, footprint
// spread at oblique incidence, mixed pixels at depth edges; IMU scale-factor errors,
// saturation and outages (samples absent). See LidarConfig and ImuConfig.
//
// Determinism: everything derives from SimConfig::seed through std::seed_seq; a scan is a pure
// function of (seed, scan index), so scans can be generated in any order and in memory.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/sim/guided_motion.h"
#include "ctlio/sim/scan_pattern.h"
#include "ctlio/sim/worlds.h"

namespace ctlio::sim {

// The seed of the documented experiment: arXiv 2403.05968 (the paper).
inline constexpr uint64_t kExperimentSeed = 2403059680ULL;

enum class Regime { kSlow, kMedium, kFast, kWalking, kVehicle };
const char* RegimeName(Regime r);
// "slow" | "medium" | "fast" | "walking" | "vehicle"; throws otherwise.
Regime ParseRegime(const std::string& name);

struct AxisMotion {
  double amplitude = 0.0;  // m/s or rad/s
  double frequency = 0.0;  // Hz
};

struct MotionProfile {
  std::array<AxisMotion, 6> axes{};  // [v_x v_y v_z ω_x ω_y ω_z]
  double start_s = 0.2;              // stationary before this time
  bool guided = false;               // carried along the world's path by `guide`
  GuideProfile guide;
};

// Draws the six axes of sequence `index` of a regime (SPEC §6): slow: linear U(0.1, 0.5) m/s @
// U(0.5, 1) Hz, no rotation; medium: linear U(0.5, 1) @ U(1, 2), angular U(0.5, 1) rad/s @
// U(2, 4); fast: linear U(1, 2) @ U(2, 4), angular U(1, 2) @ U(4, 8). Axis j of sequence i uses
// std::seed_seq{seed, regime, i} (mt19937_64), amplitude then frequency, axes in order.
// Walking and vehicle (guided; same stream, draws in this order): walking: start fraction
// U(0, 1), speed U(1.2, 1.6) m/s, step frequency f U(1.7, 2.1) Hz, vertical bob U(2, 4) cm @ f,
// lateral sway U(2, 4) cm @ f/2, speed wave U(0.05, 0.15) m/s @ f, head turns U(0.2, 0.5) rad @
// U(0.1, 0.3) Hz and U(0.05, 0.15) rad @ U(0.5, 1) Hz, pitch U(0.03, 0.08) rad @ f, roll
// U(0.02, 0.05) rad @ f/2; sensor 1.6 m above the floor, 1 s start ramp. Vehicle: start fraction,
// speed U(8, 14) m/s, speed wave U(0.5, 1.5) m/s @ U(0.02, 0.06) Hz, lane wander U(0.05, 0.2) m @
// U(0.05, 0.1) Hz, suspension U(0.5, 1.5) cm @ U(1, 2) Hz, pitch and roll U(0.005, 0.015) rad @
// U(0.8, 1.5) Hz, yaw jitter U(0.002, 0.006) rad @ U(0.3, 0.6) Hz; sensor 1.9 m high, start ramp
// speed / 2.5 m/s² long.
MotionProfile DrawMotion(Regime regime, int index, uint64_t seed = kExperimentSeed);

// Effects of a real lidar unit (sensor_effects.h: the families' values; defaults off).
struct SensorEffects {
  // Fixed per-beam angle errors (σ, degrees): the ray leaves at the true angles, the point is
  // reported along the nominal ones (an uncalibrated sensor).
  double elevation_error_deg = 0.0;
  double azimuth_error_deg = 0.0;
  double range_offset_sigma = 0.0;  // σ of a fixed per-beam range offset [m] (calibration)
  // Footprint spread: a beam of divergence δ lights a spot r·δ wide; on a surface at incidence θ
  // its depths span r·δ·tanθ, a uniform spread of σ = r·δ·tanθ/√12 added to σ(r) (tanθ ≤ 20).
  double beam_divergence_rad = 0.0;
  // Mixed pixels: where the true range jumps by more than `mixed_pixel_min_gap` [m] between this
  // ray and its neighbour along the ring (the previous kept firing of the beam), the footprint
  // straddles both surfaces and, with this probability, the return lies between them:
  // r + u·(r_neighbour − r), u ~ U(0, 1).
  double mixed_pixel_probability = 0.0;
  double mixed_pixel_min_gap = 0.5;
  // Grazing dropouts: a return is lost with probability (θ − start)/(90° − start) for incidence
  // θ > start [deg] (weak, spread-out echoes); 90 = off.
  double grazing_dropout_start_deg = 90.0;
  bool Any() const;
};

struct LidarConfig {
  int beams = 128;
  double min_elevation_deg = -25.0;
  double max_elevation_deg = 15.0;
  int firings_per_revolution = 1800;
  double rate_hz = 10.0;
  double range_noise = 0.02;  // σ [m]
  double min_range = 0.3;     // returns closer than this are dropped
  double max_range = 200.0;   // and farther than this
  int firing_decimation = 1;  // keep every n-th firing (all beams of a kept firing)
  // Realism (defaults off). σ(r) = range_noise + range_noise_per_m·r.
  double range_noise_per_m = 0.0;
  double dropout = 0.0;             // probability that a return is lost at random
  double max_incidence_deg = 90.0;  // returns hitting a surface more obliquely are lost
  // Weak echoes: received power ∝ cos θ / r², so a return needs r ≤ reflect_range·√cos θ
  // (θ = incidence angle); 0 = off.
  double reflect_range = 0.0;
  // Effects of a real sensor unit (sensor_effects.h; defaults off). `unit_seed` draws the fixed
  // per-unit errors (the beam-angle errors and range offsets of `effects`) so that every sequence
  // recorded with one unit shares them; 0: from SimConfig::seed, as before.
  uint64_t unit_seed = 0;
  SensorEffects effects;
  // A datasheet's per-beam elevations [deg], one per beam in ring order; empty: `beams` evenly
  // spaced over [min, max]_elevation_deg (sensor_models.h).
  std::vector<double> elevations_deg;
  // A non-repetitive (Livox) scan head: `beams` lines fired together at each of the
  // firings_per_revolution firings of a frame, in directions PatternDirection (scan_pattern.h);
  // the beam-angle errors do not apply to it.
  ScanPattern pattern;
};

// An interval without IMU samples, in seconds since the sequence start: [start, start + length).
struct ImuOutage {
  double start_s = 0.0;
  double length_s = 0.0;
};
// "5.0:0.5,12:2" → {{5, 0.5}, {12, 2}}; throws on malformed text.
std::vector<ImuOutage> ParseImuOutages(const std::string& text);

struct ImuConfig {
  double rate_hz = 200.0;
  double accel_noise = 0.02;  // σ_a per sample [m/s²]
  double gyro_noise = 0.01;   // σ_g per sample [rad/s]
  Vec3 accel_bias = Vec3::Constant(0.05);
  Vec3 gyro_bias = Vec3::Constant(0.05);
  double accel_bias_walk = 0.0;  // σ of the bias random walk [m/s² / √s]; 0 = constant
  double gyro_bias_walk = 0.0;   // [rad/s / √s]
  bool body_centric = false;     // the paper's model (no ω×v) instead of the exact specific force
  double gravity = 9.81;
  // Realism (defaults off). Reading = clamp((1 + s)∘truth + b + n, ±limit) per axis, s the
  // scale-factor error; limit 0 = no saturation.
  Vec3 accel_scale = Vec3::Zero();
  Vec3 gyro_scale = Vec3::Zero();
  double accel_limit = 0.0;  // [m/s²]
  double gyro_limit = 0.0;   // [rad/s]
  // Outages: the samples inside are absent (in memory and in every layout written). Given
  // intervals, plus random ones: a Poisson process of `outage_rate` per second over the sequence
  // with lengths U(outage_length_min, outage_length_max).
  std::vector<ImuOutage> outages;
  double outage_rate = 0.0;
  double outage_length_min = 0.1, outage_length_max = 1.0;
  // Mounting and clock: T_body_imu (identity: the IMU frame is the body frame), and the time of
  // the first sample after the sequence start [s] (samples at start + offset + k/rate).
  SE3 body_from_imu;
  double clock_offset_s = 0.0;
  // Stamp offset δ [s]: the sample measuring the motion at t carries the stamp t − δ (an IMU clock
  // δ behind the lidar's); δ is what the odometry's online time-offset calibration should find
  // (recorded as the IMU's true_time_offset_s). 0: stamps are the true times.
  double stamp_offset_s = 0.0;
};

struct SimConfig {
  RoomConfig room;    // the box world
  WorldConfig world;  // which world (box by default)
  LidarConfig lidar;
  ImuConfig imu;
  MotionProfile motion;
  double duration_s = 20.0;
  int64_t start_ns = 0;                                        // absolute time of t = 0
  SE3 world_from_imu0 = SE3(Mat3::Identity(), Vec3(0, 0, 2));  // T_wb(0) (unguided motion)
  SE3 imu_from_lidar;                                          // T_bl (identity by default)
  // The extrinsic handed out as the sensor setup's (dataset file, ImuFromLidar), when it differs
  // from the true imu_from_lidar the lidar moves with (calibration experiments,
  // extrinsic_error.h); unset = the truth.
  std::optional<SE3> nominal_imu_from_lidar;
  // Further IMUs (IMU 1, 2, ...; `imu` is IMU 0). Each gets its own noise stream, so IMU 0's
  // samples are the same with or without them.
  std::vector<ImuConfig> extra_imus;
  uint64_t seed = kExperimentSeed;   // noise seed
  double integration_step_s = 1e-4;  // ground-truth pose grid
};

// The configuration of sequence `index` of a regime: DrawMotion + noise seed {seed, regime, index}.
// In a world other than the box, slow/medium/fast are guided along its path at 0.5/1/1.5 m/s,
// 1.5 m above the floor, from a start fraction drawn from {seed, regime, index, 0x57A7}.
SimConfig ExperimentConfig(Regime regime, int index, uint64_t seed = kExperimentSeed,
                           WorldKind world = WorldKind::kBox);

class LidarInertialSim {
 public:
  explicit LidarInertialSim(const SimConfig& config);

  const SimConfig& config() const { return config_; }
  double Seconds(int64_t t_ns) const { return 1e-9 * double(t_ns - config_.start_ns); }

  // Ground truth at time t [s since start]: body twist [v; ω], its rate, and T_wb (integrated with
  // the 4th-order Magnus method on a grid of `integration_step_s`, plus one partial step).
  Vec6 BodyTwist(double t) const;
  Vec6 BodyTwistRate(double t) const;
  SE3 WorldFromImu(double t) const;
  SE3 WorldFromLidar(double t) const { return WorldFromImu(t) * config_.imu_from_lidar; }
  // Noise-free IMU reading at t (biases excluded) of an IMU at T_body_imu (default: the body
  // frame).
  io::ImuSample TrueImu(double t, const SE3& body_from_imu = SE3()) const;

  // IMU 0, 1, ...: the configuration (imu, then extra_imus).
  size_t NumImus() const { return imu_.size(); }
  const ImuConfig& ImuConfigOf(size_t j) const {
    return j == 0 ? config_.imu : config_.extra_imus.at(j - 1);
  }
  // The noisy IMU stream of IMU j with biases, every sample of the sequence (tagged imu = j).
  const std::vector<io::ImuSample>& Imu(size_t j = 0) const { return imu_.at(j); }
  // Every IMU's samples in one time-sorted stream (the data source hands this out).
  const std::vector<io::ImuSample>& AllImu() const { return all_imu_; }
  // Bias [b_a; b_g] of IMU `imu` at its sample j (constant unless a random walk is configured).
  const std::vector<Vec6>& ImuBiases(size_t imu = 0) const { return biases_.at(imu); }

  size_t NumScans() const;
  int64_t ScanStartNs(size_t k) const;
  int64_t FiringTimeNs(size_t k, int firing) const;
  // Scan k in the lidar frame with absolute per-point times and ring indices (line indices for a
  // non-repetitive pattern).
  io::PointCloud Scan(size_t k) const;

  // Range along a unit ray from a world point (interior of the room, nearest obstacle), or +inf.
  double CastRay(const Vec3& origin, const Vec3& direction) const;
  // The world's geometry and path; the realised IMU outages (given and random).
  const World& world() const { return world_; }
  const std::vector<ImuOutage>& ImuOutages(size_t imu = 0) const { return outages_.at(imu); }

 private:
  SimConfig config_;
  World world_;
  double path_start_ = 0.0;                            // arc length where the guided motion starts
  std::vector<std::vector<ImuOutage>> outages_;        // per IMU
  std::vector<double> beam_el_error_, beam_az_error_;  // radians, per beam
  std::vector<double> beam_range_offset_;              // metres, per beam (unit effects)
  std::vector<SE3> grid_;                              // T_wb at multiples of integration_step_s
  std::vector<std::vector<io::ImuSample>> imu_;        // per IMU
  std::vector<std::vector<Vec6>> biases_;              // per IMU
  std::vector<io::ImuSample> all_imu_;
  std::vector<double> cos_el_, sin_el_, cos_az_, sin_az_;
  // With beam-angle errors: where the rays really go, per beam (elevation) and per kept firing
  // × beam (azimuth, index f·beams + b), computed once instead of five trigonometric calls a ray.
  std::vector<double> cos_el_ray_, sin_el_ray_, cos_az_ray_, sin_az_ray_;
  SE3 MagnusStep(const SE3& T, double t, double h) const;
  // The body-rate motion P (SPEC §6 sinusoids) and its pose integrated on the grid.
  Vec6 LocalTwist(double t) const;
  Vec6 LocalTwistRate(double t) const;
  SE3 LocalPose(double t) const;
  // The nearest surface along a ray (normals only where realism needs them in the box room).
  // `time` [s since the start] places the world's moving people (Scene::movers).
  RayHit Cast(const Vec3& o, const Vec3& d, double time = 0.0) const;
  // Scan k with the ray directions `directions(f, b, t, &d_l, &d_ray)` of firing f, beam b at
  // time t (Scan: the spinning lidar's beam table or a non-repetitive pattern); one loop for both.
  template <class Directions>
  io::PointCloud ScanRays(size_t k, const Directions& directions) const;
  // IMU j's samples, biases and outages (IMU 0 draws from the single-IMU streams).
  void GenerateImu(size_t j);
  void ApplyImuOutages(size_t j);
};

// The simulator as a data source, generating each scan in memory when asked (SPEC §6: a
// full-resolution sequence would not fit on disk 60 times). Ground truth: T_world_lidar at every
// IMU time and every scan end.
class SimulatedSource : public io::DataSource {
 public:
  explicit SimulatedSource(const SimConfig& config, std::string name = "sim");
  std::string Name() const override { return name_; }
  size_t NumScans() const override { return sim_.NumScans(); }
  bool Next(io::ScanFrame* frame) override;
  // The nominal extrinsic (SimConfig::nominal_imu_from_lidar if set); the truth below.
  SE3 ImuFromLidar() const override {
    return sim_.config().nominal_imu_from_lidar.value_or(sim_.config().imu_from_lidar);
  }
  std::optional<SE3> TrueImuFromLidar() const override { return sim_.config().imu_from_lidar; }
  std::optional<std::vector<io::StampedPose>> GroundTruth() const override;
  std::optional<double> Gravity() const override { return sim_.config().imu.gravity; }
  std::vector<io::ImuInfo> Imus() const override;
  const LidarInertialSim& simulator() const { return sim_; }

 private:
  LidarInertialSim sim_;
  std::string name_;
  size_t next_ = 0;
  size_t imu_cursor_ = 0;
};

}  // namespace ctlio::sim
