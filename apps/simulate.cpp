// ctlio_simulate: writes one sequence of the lidar-inertial simulator (SPEC §6) as a dataset
// folder, in ctlio's own layout (default) or the Newer College 2020 layout, with ground truth, or
// as a ROS 1 bag (--layout rosbag: --output is the .bag file; ground truth on /ground_truth and in
// <output without .bag>_ground_truth.tum) or a ROS 2 bag folder (--layout ros2: MCAP, or
// ros2_sqlite3: SQLite; ground truth also in <output>_ground_truth.tum).
//
//   ctlio_simulate --regime=fast --index=3 --output=/tmp/fast_03 [--layout=newer_college]
//                  [--firing_decimation=4] [--duration=20] [--body_centric] [--pillars=4]
//   ctlio_simulate --world=street --regime=vehicle --output=/tmp/street [--topview=street.svg]
//                  [--imu_dropout=5.0:0.5,12:2] [--lidar_dropout=0.1] [--gyro_limit=4] ...
//   ctlio_simulate --preset=newer_college --layout=newer_college --index=0 --output=/tmp/nc_00
//
// Realism and outage flags default to off (the simulator of SPEC §6). A preset (presets.h) sets
// sensor, IMU, extrinsic, world, regime and duration; flags given explicitly override it.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>

#include "common/command_line.h"
#include "common/preset_flags.h"
#include "ctlio/eval/geometry_statistics.h"
#include "ctlio/io/bag_writer.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/imu_specs.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "ctlio/sim/sensor_models.h"

DEFINE_string(output, "", "Dataset folder to write (required)");
DEFINE_string(preset, "",
              "Recording preset: none | newer_college | kitti (explicit flags override it)");
DEFINE_string(sensor, "",
              "Sensor model: os0_128 | os1_64 | os1_128 | vlp16 | hdl32e | pandar_xt32 | mid360 | "
              "avia (lidar, IMU, extrinsic and, in bags, the driver's fields, topics and frames; "
              "'list' prints them; explicit flags override it)");
DEFINE_string(livox_format, "custom",
              "--sensor mid360|avia, bag layouts: custom (livox_ros_driver2/CustomMsg) | "
              "pointcloud2 (the driver's xfer_format 0)");
DEFINE_string(layout, "ctlio",
              "Layout: ctlio | newer_college | rosbag (a .bag file) | ros2 (a ROS 2 bag folder, "
              "MCAP) | ros2_sqlite3 (a ROS 2 bag folder, SQLite)");
DEFINE_string(bag_compression, "none",
              "--layout rosbag: chunk compression none | lz4 | bz2; --layout ros2: none | zstd | "
              "lz4");
DEFINE_string(regime, "fast", "Motion regime: slow | medium | fast | walking | vehicle");
DEFINE_string(world, "box",
              "World: box | street | corridor | park | indoor | quad | town | office");
DEFINE_uint64(world_seed, ctlio::sim::kExperimentSeed, "Seed of the world's geometry");
DEFINE_string(geometry_report, "",
              "Scan indices, comma separated (e.g. 0,50): print the local-geometry statistic of "
              "these sweeps (ctlio_geometry_report's table) and the time to simulate each, and "
              "write nothing (--output not needed)");
DEFINE_string(topview, "", "Also write a top view of the world and its path (SVG) to this file");
DEFINE_double(range_noise_per_m, 0.0,
              "Range noise growing with range: σ = 0.02 m + k·r, k [m/m]; 0 = constant 2 cm");
DEFINE_double(lidar_dropout, 0.0, "Probability that a lidar return is lost at random [0, 1]");
DEFINE_double(max_incidence_deg, 90.0, "Returns at a larger incidence angle [deg] are lost");
DEFINE_double(reflect_range, 0.0,
              "Weak echoes: a return needs r ≤ this·√cos(incidence) [m]; 0 = off");
DEFINE_double(beam_elevation_error_deg, 0.0, "σ of fixed per-beam elevation errors [deg]");
DEFINE_double(beam_azimuth_error_deg, 0.0, "σ of fixed per-beam azimuth errors [deg]");
DEFINE_string(sensor_effects, "auto",
              "The lidar unit's effects (sim sensor_effects.h: per-beam angle and range errors, "
              "footprint spread, mixed pixels, grazing dropouts): auto (the preset's or --sensor's "
              "family under a preset; --sensor's family in quad, town and office; none "
              "otherwise) | off | ouster | hdl64 | velodyne | hesai | livox");
DEFINE_double(beam_range_offset_sigma, 0.0, "σ of fixed per-beam range offsets [m]");
DEFINE_double(beam_divergence_mrad, 0.0,
              "Footprint depth spread r·δ·tan(incidence)/√12 added to the range noise [mrad]");
DEFINE_double(mixed_pixels, 0.0, "Probability of a mixed pixel at a depth edge [0, 1]");
DEFINE_double(mixed_pixel_gap, 0.5, "Range jump that makes a depth edge for --mixed_pixels [m]");
DEFINE_double(grazing_dropout_start_deg, 90.0,
              "Returns at incidence θ above this are lost with probability (θ−this)/(90°−this)");
DEFINE_string(accel_scale, "0,0,0",
              "Accelerometer scale-factor errors s (x,y,z; dimensionless): (1+s)·f");
DEFINE_string(gyro_scale, "0,0,0", "Gyro scale-factor errors s (x,y,z; dimensionless): (1+s)·ω");
DEFINE_double(accel_limit, 0.0, "Accelerometer saturation per axis [m/s²]; 0 = none");
DEFINE_double(gyro_limit, 0.0, "Gyro saturation per axis [rad/s]; 0 = none");
DEFINE_string(imu_dropout, "", "IMU outages start:length [s], e.g. 5.0:0.5,12:2");
DEFINE_string(imus, "",
              "Further IMUs (IMU 1, 2, ...), ';'-separated key=value lists: rate, xyz, rpy, "
              "offset, accel_noise, gyro_noise, accel_bias, gyro_bias, outage (apps/sim "
              "imu_specs.h), e.g. rate=400,xyz=0.3:0:0,offset=0.0013");
DEFINE_double(imu_stamp_offset, 0.0,
              "IMU 0's sample of the motion at t is stamped t - this [s] (a clock offset for the "
              "odometry's online calibration; recorded as true_time_offset_s in ctlio_sim.yaml; "
              "other IMUs: stamp_offset= in --imus)");
DEFINE_double(imu_outage_rate, 0.0, "Random IMU outages per second [1/s] (Poisson); 0 = none");
DEFINE_double(imu_outage_min, 0.1, "Shortest random IMU outage [s]");
DEFINE_double(imu_outage_max, 1.0, "Longest random IMU outage [s]");
DEFINE_int32(index, 0, "Sequence index within the regime (the experiment uses 0..19)");
DEFINE_uint64(seed, ctlio::sim::kExperimentSeed, "Experiment seed (documented default)");
DEFINE_double(duration, 20.0, "Sequence length [s]");
DEFINE_double(start_s, 0.0,
              "Absolute time of the sequence start [s] (0 = 0, or 1 s for a bag: ROS 1 bags cannot "
              "hold time 0; and for the Newer College layout with --imu_stamp_offset > 0)");
DEFINE_int32(firing_decimation, 1, "Keep every n-th lidar firing (1 = full resolution)");
DEFINE_int32(beams, 128, "Lidar beams");
DEFINE_bool(body_centric, false, "Generate the paper's body-centric accelerometer (no ω×v)");
DEFINE_double(bias_walk_accel, 0.0, "Accelerometer bias random walk [m/s²/√s]");
DEFINE_double(bias_walk_gyro, 0.0, "Gyro bias random walk [rad/s/√s]");
DEFINE_int32(pillars, 0, "Interior 1 m × 1 m pillars placed at random (seeded) in the room");
DEFINE_bool(ground_truth, true, "Write the ground-truth trajectory");
DEFINE_string(extrinsic_error, "",
              "Write a NOMINAL lidar->IMU extrinsic off the true one by <angle>deg[@ax:ay:az],"
              "<distance>m[@dx:dy:dz] (axis/direction drawn per --index when omitted), e.g. "
              "3deg,0.10m (apps/sim extrinsic_error.h), in every layout: ctlio_sim.yaml (the "
              "truth in true_imu_from_lidar), a bag's /tf_static, the Newer College layout's "
              "published extrinsic (the truth off it); bags and Newer College folders get the "
              "truth as a config overlay, <bag stem>_true_calibration.yaml / "
              "<folder>/true_calibration.yaml");
DEFINE_bool(newer_college_extrinsic, false,
            "Use the Newer College lidar→IMU extrinsic instead of identity (always used with "
            "--layout=newer_college, which cannot carry another)");

namespace {

// A flag applies unless a preset is chosen and the flag was not given explicitly.
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  return ctlio::apps::Given(!FLAGS_preset.empty() || !FLAGS_sensor.empty(), flag, value);
}

// "a,b,c" → Vec3 (one number repeats on all axes).
// The simulated calibration as an odometry config overlay (docs/user-guide/configuration.md,
// "Composing configs"): the true extrinsic and IMU 0's clock offset, so that
// --config my.yaml,<this> runs with the true values; comments give the nominal the data carry.
void WriteTrueCalibration(const std::string& path, const ctlio::sim::SimConfig& config,
                          double time_offset_s) {
  const ctlio::SE3& T = config.imu_from_lidar;
  const ctlio::SE3 nominal = config.nominal_imu_from_lidar.value_or(T);
  std::ofstream f = ctlio::io::OpenForWriting(path);
  f << std::setprecision(12)
    << "# ctlio_simulate: the true lidar-IMU calibration of this recording, as an odometry config\n"
    << "# overlay (--config my.yaml," << std::filesystem::path(path).filename().string()
    << " runs with the true values).\n# The data carry the nominal extrinsic (translation ["
    << nominal.translation().x() << ", " << nominal.translation().y() << ", "
    << nominal.translation().z() << "]) and IMU 0's samples stamped " << time_offset_s
    << " s early.\ncalibration:\n  time_offset_s: [" << time_offset_s << "]\nextrinsic:\n"
    << "  rotation: [";
  const ctlio::Mat3 R = T.rotation();
  for (int i = 0; i < 9; ++i) f << (i > 0 ? ", " : "") << R(i / 3, i % 3);
  f << "]\n  translation: [" << T.translation().x() << ", " << T.translation().y() << ", "
    << T.translation().z() << "]\n";
  ctlio::io::CloseChecked(f, path);
}

ctlio::Vec3 ParseVec3(const std::string& flag, const std::string& text) {
  std::stringstream in(text);
  std::vector<double> v;
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::runtime_error("--" + flag + "='" + text + "': expected x,y,z numbers");
    }
  }
  if (v.size() == 1) return ctlio::Vec3::Constant(v[0]);
  if (v.size() != 3)
    throw std::runtime_error("--" + flag + "='" + text + "': expected 1 or 3 numbers");
  return ctlio::Vec3(v[0], v[1], v[2]);
}

}  // namespace

constexpr char kUsage[] =
    "ctlio_simulate: writes one sequence of the lidar-inertial simulator as a dataset folder\n"
    "(ctlio's layout or Newer College's) or as a ROS 1 or ROS 2 bag, with ground truth.\n"
    "\n"
    "  ctlio_simulate --regime=fast --index=3 --output=/tmp/fast_03 [--layout=newer_college]\n"
    "  ctlio_simulate --world=street --regime=vehicle --output=/tmp/street --topview=street.svg\n"
    "  ctlio_simulate --preset=newer_college --layout=rosbag --output=/tmp/nc_00.bag\n"
    "  ctlio_simulate --layout=ros2 --bag_compression=zstd --output=/tmp/fast_00_ros2";

namespace {

// The bag writers' options: ground truth as asked, and with --sensor its driver's fields, per-point
// time, topics, frames and accelerometer unit (the same in ROS 1 and ROS 2 bags).
ctlio::io::RosbagWriteOptions BagWriteOptions() {
  ctlio::io::RosbagWriteOptions o;
  o.write_ground_truth = FLAGS_ground_truth;
  if (!FLAGS_sensor.empty()) {
    ctlio::io::DriverConvention d = ctlio::sim::FindSensorModel(FLAGS_sensor).driver;
    if (d.format == ctlio::io::PointFormat::kLivoxCustomMsg &&
        FLAGS_livox_format == "pointcloud2") {
      d.format = ctlio::io::PointFormat::kLivoxPointCloud2;
    }
    o.UseDriver(d);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (FLAGS_sensor == "list") {
    std::cout << ctlio::sim::ListSensorModels();
    return 0;
  }
  if (FLAGS_output.empty() && FLAGS_geometry_report.empty()) {
    std::cerr << "--output is required\n";
    return 2;
  }
  try {
    using namespace ctlio;
    // Counts and rates, before any work (docs/user-guide/bad-input.md). Times are int64
    // nanoseconds (±9.22e9 s); a ROS 1 bag's are uint32 seconds: the sequence must fit after
    // --start_s (the duration is at most 3600 s).
    using ctlio::apps::RequireInRange;
    RequireInRange("index", FLAGS_index, 0, 1'000'000);
    RequireInRange("pillars", FLAGS_pillars, 0, 10'000);
    RequireInRange("imu_outage_rate", FLAGS_imu_outage_rate, 0.0, 100.0, " per second");
    if (FLAGS_layout == "rosbag") {
      RequireInRange("start_s", FLAGS_start_s, 0.0, 4.29e9,
                     " s (a ROS 1 bag's times are unsigned 32-bit seconds)");
    } else if (FLAGS_layout == "ros2" || FLAGS_layout == "ros2_sqlite3") {
      RequireInRange("start_s", FLAGS_start_s, 0.0, 2.147e9,
                     " s (a ROS 2 message's times are signed 32-bit seconds)");
    } else {
      RequireInRange("start_s", FLAGS_start_s, -9.2e9, 9.2e9,
                     " s (times are int64 nanoseconds, at most ±9.22e9 s)");
    }
    const sim::Preset preset = sim::ParsePreset(FLAGS_preset);
    sim::SimOverrides given;
    if (auto r = Given("regime", FLAGS_regime)) given.regime = sim::ParseRegime(*r);
    if (auto w = Given("world", FLAGS_world)) given.world = sim::ParseWorld(*w);
    given.duration_s = Given("duration", FLAGS_duration);
    given.beams = Given("beams", FLAGS_beams);
    given.firing_decimation = Given("firing_decimation", FLAGS_firing_decimation);
    given.range_noise_per_m = Given("range_noise_per_m", FLAGS_range_noise_per_m);
    given.body_centric = Given("body_centric", FLAGS_body_centric);
    given.accel_bias_walk = Given("bias_walk_accel", FLAGS_bias_walk_accel);
    given.gyro_bias_walk = Given("bias_walk_gyro", FLAGS_bias_walk_gyro);
    given.newer_college_extrinsic = Given("newer_college_extrinsic", FLAGS_newer_college_extrinsic);
    if (!FLAGS_sensor.empty()) given.sensor = FLAGS_sensor;
    if (FLAGS_sensor_effects != "auto") given.sensor_effects = FLAGS_sensor_effects;
    if (FLAGS_livox_format != "custom" && FLAGS_livox_format != "pointcloud2") {
      throw std::runtime_error("--livox_format '" + FLAGS_livox_format + "': custom | pointcloud2");
    }
    const sim::Regime regime = given.regime.value_or(sim::PresetRegime(preset));
    const sim::WorldKind world = given.world.value_or(sim::PresetWorld(preset));
    const std::string regime_name = sim::RegimeName(regime), world_name = sim::WorldName(world);
    if (FLAGS_pillars > 0 && world != sim::WorldKind::kBox) {
      throw std::runtime_error("--pillars is a box-world option");
    }
    sim::SimConfig config = sim::PresetConfig(preset, FLAGS_index, FLAGS_seed, given);
    // inf wrote 0 scans with exit 0, nan failed in vector::reserve.
    if (!(config.duration_s > 0.0 && config.duration_s <= 3600.0)) {
      throw std::runtime_error("--duration must be in (0, 3600] s");
    }
    if (config.lidar.firing_decimation < 1 || config.lidar.beams < 1) {
      throw std::runtime_error("--firing_decimation and --beams must be >= 1");
    }
    config.world.seed = FLAGS_world_seed;
    // Lidar realism flags: each given one replaces the preset's (sensor effects) value.
    auto& L = config.lidar;
    auto set = [](const char* flag, double value, double* target) {
      if (!gflags::GetCommandLineFlagInfoOrDie(flag).is_default) *target = value;
    };
    set("lidar_dropout", FLAGS_lidar_dropout, &L.dropout);
    set("max_incidence_deg", FLAGS_max_incidence_deg, &L.max_incidence_deg);
    set("reflect_range", FLAGS_reflect_range, &L.reflect_range);
    set("beam_elevation_error_deg", FLAGS_beam_elevation_error_deg, &L.effects.elevation_error_deg);
    set("beam_azimuth_error_deg", FLAGS_beam_azimuth_error_deg, &L.effects.azimuth_error_deg);
    set("beam_range_offset_sigma", FLAGS_beam_range_offset_sigma, &L.effects.range_offset_sigma);
    set("beam_divergence_mrad", 1e-3 * FLAGS_beam_divergence_mrad, &L.effects.beam_divergence_rad);
    set("mixed_pixels", FLAGS_mixed_pixels, &L.effects.mixed_pixel_probability);
    set("mixed_pixel_gap", FLAGS_mixed_pixel_gap, &L.effects.mixed_pixel_min_gap);
    set("grazing_dropout_start_deg", FLAGS_grazing_dropout_start_deg,
        &L.effects.grazing_dropout_start_deg);
    auto& I = config.imu;
    I.accel_scale = ParseVec3("accel_scale", FLAGS_accel_scale);
    I.gyro_scale = ParseVec3("gyro_scale", FLAGS_gyro_scale);
    I.accel_limit = FLAGS_accel_limit;
    I.gyro_limit = FLAGS_gyro_limit;
    I.outages = sim::ParseImuOutages(FLAGS_imu_dropout);
    I.stamp_offset_s = FLAGS_imu_stamp_offset;
    I.outage_rate = FLAGS_imu_outage_rate;
    I.outage_length_min = FLAGS_imu_outage_min;
    I.outage_length_max = FLAGS_imu_outage_max;
    config.extra_imus = sim::ParseImuSpecs(FLAGS_imus, I);
    // The Newer College layout carries no extrinsic and is read with the published one.
    if (FLAGS_layout == "newer_college") config.imu_from_lidar = io::NewerCollegeImuFromLidar();
    const sim::ExtrinsicError extrinsic_error = sim::ParseExtrinsicError(FLAGS_extrinsic_error);
    if (!extrinsic_error.IsZero()) {
      if (FLAGS_layout == "newer_college") {
        // The layout is read with the published extrinsic, so that one is the nominal and the
        // lidar moves with a truth off it by the inverse error: C_nom = Exp(θa)·C_true and
        // p_nom = p_true + s·d (extrinsic_error.h) with Exp(θa), s·d the nominal of the identity.
        const SE3 e = sim::NominalExtrinsic(SE3(), extrinsic_error, FLAGS_seed, FLAGS_index);
        const SE3 nominal = config.imu_from_lidar;
        config.imu_from_lidar = SE3(e.rotation().transpose() * nominal.rotation(),
                                    nominal.translation() - e.translation());
        config.nominal_imu_from_lidar = nominal;
      } else {
        config.nominal_imu_from_lidar =
            sim::NominalExtrinsic(config.imu_from_lidar, extrinsic_error, FLAGS_seed, FLAGS_index);
      }
    }
    config.start_ns = std::llround(FLAGS_start_s * 1e9);
    if (FLAGS_layout == "rosbag" && config.start_ns == 0) config.start_ns = 1'000'000'000;
    // IMU stamps early by a clock offset would be negative at 0, which the Newer College CSV
    // (sec, nsec) cannot hold.
    if (FLAGS_layout == "newer_college" && config.start_ns == 0 && FLAGS_imu_stamp_offset > 0) {
      config.start_ns = 1'000'000'000;
    }
    std::mt19937_64 rng(FLAGS_seed + 17);
    std::uniform_real_distribution<double> u(-40.0, 40.0);
    for (int i = 0; i < FLAGS_pillars; ++i) {
      const Vec3 c(u(rng), u(rng), 0.0);
      if (c.head<2>().norm() < 5.0) {  // keep the start area free
        --i;
        continue;
      }
      config.room.obstacles.push_back({c + Vec3(-0.5, -0.5, 0), c + Vec3(0.5, 0.5, 10)});
    }

    std::ostringstream yaml;
    yaml << "{preset: " << sim::PresetName(preset)
         << (FLAGS_sensor.empty() ? "" : ", sensor: " + FLAGS_sensor) << ", world: " << world_name
         << ", world_seed: " << FLAGS_world_seed << ", regime: " << regime_name
         << ", index: " << FLAGS_index << ", seed: " << FLAGS_seed
         << ", duration_s: " << config.duration_s
         << ", firing_decimation: " << config.lidar.firing_decimation
         << ", beams: " << config.lidar.beams
         << ", firings_per_revolution: " << config.lidar.firings_per_revolution
         << ", elevation_deg: [" << config.lidar.min_elevation_deg << ", "
         << config.lidar.max_elevation_deg << "], lidar_rate_hz: " << config.lidar.rate_hz
         << ", range_noise: " << config.lidar.range_noise << ", imu_rate_hz: " << config.imu.rate_hz
         << ", accel_noise: " << config.imu.accel_noise << ", gyro_noise: " << config.imu.gyro_noise
         << ", bias_walk_accel: " << config.imu.accel_bias_walk
         << ", bias_walk_gyro: " << config.imu.gyro_bias_walk
         << ", body_centric: " << (config.imu.body_centric ? "true" : "false")
         << ", pillars: " << FLAGS_pillars
         << ", range_noise_per_m: " << config.lidar.range_noise_per_m
         << ", lidar_dropout: " << L.dropout << ", max_incidence_deg: " << L.max_incidence_deg
         << ", reflect_range: " << L.reflect_range
         << ", beam_elevation_error_deg: " << L.effects.elevation_error_deg
         << ", beam_azimuth_error_deg: " << L.effects.azimuth_error_deg;
    if (L.unit_seed != 0 || L.effects.range_offset_sigma > 0 || L.effects.beam_divergence_rad > 0 ||
        L.effects.mixed_pixel_probability > 0 || L.effects.grazing_dropout_start_deg < 90) {
      yaml << ", sensor_unit_seed: " << L.unit_seed
           << ", beam_range_offset_sigma: " << L.effects.range_offset_sigma
           << ", beam_divergence_rad: " << L.effects.beam_divergence_rad
           << ", mixed_pixels: " << L.effects.mixed_pixel_probability
           << ", mixed_pixel_gap: " << L.effects.mixed_pixel_min_gap
           << ", grazing_dropout_start_deg: " << L.effects.grazing_dropout_start_deg;
    }
    yaml << ", accel_scale: [" << FLAGS_accel_scale << "], gyro_scale: [" << FLAGS_gyro_scale
         << "], accel_limit: " << FLAGS_accel_limit << ", gyro_limit: " << FLAGS_gyro_limit
         << ", imu_outage_rate: " << FLAGS_imu_outage_rate << ", imu_outage_length: ["
         << FLAGS_imu_outage_min << ", " << FLAGS_imu_outage_max << "], imus: \"" << FLAGS_imus
         << "\", axes: [";
    for (int j = 0; j < 6; ++j) {
      yaml << (j ? ", " : "") << "[" << config.motion.axes[j].amplitude << ", "
           << config.motion.axes[j].frequency << "]";
    }
    yaml << "]";
    if (config.motion.guided) {
      const sim::GuideProfile& g = config.motion.guide;
      yaml << ", guide: {start_fraction: " << g.start_fraction << ", speed: " << g.speed
           << ", height: " << g.height << "}";
    }
    yaml << "}";

    const auto t0 = std::chrono::steady_clock::now();
    std::ostringstream name;
    name << "sim:" << (world == sim::WorldKind::kBox ? "" : world_name + "/") << regime_name << "/"
         << FLAGS_index;
    sim::SimulatedSource source(config, name.str());
    if (!FLAGS_topview.empty()) {
      sim::WriteTopViewSvg(source.simulator().world(), FLAGS_topview, "world " + world_name);
    }
    if (!FLAGS_geometry_report.empty()) {
      eval::WriteGeometryHeader(std::cout);
      for (const std::string& item : apps::SplitList(FLAGS_geometry_report)) {
        if (item.find_first_not_of("0123456789") != std::string::npos || item.size() > 9) {
          throw std::runtime_error("--geometry_report='" + FLAGS_geometry_report +
                                   "': expected scan indices, e.g. 0,50");
        }
        const size_t k = std::stoul(item);
        if (k >= source.NumScans()) {
          throw std::runtime_error("--geometry_report: scan " + item + " is not in the " +
                                   std::to_string(source.NumScans()) + " scans");
        }
        // CPU time: the machine may be shared, and the simulator runs on one thread.
        const std::clock_t c0 = std::clock();
        const io::PointCloud cloud = source.simulator().Scan(k);
        const double ms = 1e3 * double(std::clock() - c0) / CLOCKS_PER_SEC;
        eval::WriteGeometryRow(std::cout, name.str() + " scan " + item,
                               eval::ComputeGeometryStatistics(cloud.points));
        LOG(INFO) << "scan " << k << ": " << cloud.size() << " points simulated in " << ms
                  << " ms CPU";
      }
      return 0;
    }
    if (!source.simulator().ImuOutages().empty()) {
      std::ostringstream msg;
      for (const auto& o : source.simulator().ImuOutages()) {
        msg << " [" << o.start_s << ", " << o.start_s + o.length_s << ") s";
      }
      LOG(INFO) << "IMU outages (samples absent):" << msg.str();
    }
    // Progress on stderr, about every 5 % of the scans.
    auto progress = [&](size_t done, size_t total) {
      if (done != total && done % std::max<size_t>(1, total / 20) != 0) return;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "scan %zu/%zu (%3.0f %%)  %.1f s\n", done, total,
                   100.0 * double(done) / double(std::max<size_t>(total, 1)), s);
    };
    // The truth of what the data carry wrong (the nominal extrinsic, IMU 0's stamps), beside
    // the layouts that have no place for it (ctlio_sim.yaml records it in the ctlio layout).
    std::string truth_path;
    const bool ros2 = FLAGS_layout == "ros2" || FLAGS_layout == "ros2_sqlite3";
    if (FLAGS_layout == "rosbag") {
      std::string stem = FLAGS_output;
      if (stem.size() > 4 && stem.substr(stem.size() - 4) == ".bag") stem.resize(stem.size() - 4);
      truth_path = stem + "_true_calibration.yaml";
    } else if (ros2) {
      truth_path = FLAGS_output + "_true_calibration.yaml";  // beside the bag folder
    } else if (FLAGS_layout == "newer_college") {
      truth_path = FLAGS_output + "/true_calibration.yaml";
    }
    size_t n = 0;
    if (FLAGS_layout == "ctlio") {
      n = io::WriteSimFolder(source, FLAGS_output, yaml.str(), progress, FLAGS_ground_truth);
    } else if (FLAGS_layout == "newer_college") {
      n = io::WriteNewerCollege(source, FLAGS_output, progress, FLAGS_ground_truth);
    } else if (FLAGS_layout == "rosbag") {
      io::RosbagWriteOptions o = BagWriteOptions();
      o.compression = FLAGS_bag_compression;
      n = io::WriteRosbag(source, FLAGS_output, o, progress);
      if (FLAGS_ground_truth) {
        std::string stem = FLAGS_output;
        if (stem.size() > 4 && stem.substr(stem.size() - 4) == ".bag") stem.resize(stem.size() - 4);
        io::WriteTum(stem + "_ground_truth.tum", *source.GroundTruth());
      }
    } else if (ros2) {
      const io::RosbagWriteOptions o = BagWriteOptions();
      io::Ros2WriteOptions r;
      r.storage =
          FLAGS_layout == "ros2" ? io::ros2::Ros2Storage::kMcap : io::ros2::Ros2Storage::kSqlite3;
      r.compression = io::ParseRos2Compression(FLAGS_bag_compression);
      if (r.storage != io::ros2::Ros2Storage::kMcap &&
          r.compression != io::ros2::Ros2Compression::kNone) {
        throw std::runtime_error("--bag_compression applies to --layout ros2 (MCAP) only");
      }
      n = io::WriteRos2Bag(source, FLAGS_output, o, r, progress);
      if (FLAGS_ground_truth) {
        io::WriteTum(FLAGS_output + "_ground_truth.tum", *source.GroundTruth());
      }
    } else {
      throw std::runtime_error("unknown --layout '" + FLAGS_layout + "'");
    }
    if (!truth_path.empty() && (!extrinsic_error.IsZero() || FLAGS_imu_stamp_offset != 0.0)) {
      WriteTrueCalibration(truth_path, config, FLAGS_imu_stamp_offset);
      LOG(INFO) << "the true calibration (an odometry config overlay): " << truth_path;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    LOG(INFO) << "wrote " << n << " scans to " << FLAGS_output << " in " << s << " s";
  } catch (const std::exception& e) {
    std::cerr << "ctlio_simulate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
