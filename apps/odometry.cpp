// ctlio_odometry: lidar-inertial odometry on a dataset folder or on the in-memory simulator.
//
//   ctlio_odometry --dataset DIR|FILE.bag|BAG2 [--format newer_college|ctlio|kitti|rosbag|ros2]
//                  --method singer_lio|imu_input|lidar_gyro|lidar_only --config FILE --out DIR
//   (a ROS 1 bag: [--lidar_topic T --imu_topic T --preset newer_college_2020|newer_college_2021
//    --time_field F --time_unit s|ms|us|ns --time_reference relative|absolute --stamp_at
//    start|end])
//   ctlio_odometry --format sim --sim_regime fast --sim_index 0 [--sim_duration 5 ...] ...
//   ctlio_odometry --format sim --sim_imu_dropout 5:1 ...   # no IMU samples in [5 s, 6 s)
//   ctlio_odometry --format sim --sim_imus "rate=400,xyz=0.3:0:0,offset=0.0013" ...  # a 2nd IMU
//   ctlio_odometry --format sim --sim_preset newer_college --sim_index 0 \
//                  --config data/newer_college_lio.yaml --out DIR
//
// Writes DIR/trajectory.tum (T_world_lidar at every scan end, TUM `t x y z qx qy qz qw`), with
// --trajectory_rate HZ also DIR/trajectory_dense.tum (the estimate at HZ between scan poses, from
// the final estimates: continuous) and DIR/trajectory_dense_live.tum (as returned live, causal),
// DIR/scans.log (one line per scan: status, residual counts, iterations, time, the degenerate
// directions of the lidar term: docs/user-guide/outputs.md) and, when the
// source has ground truth, DIR/ground_truth.tum and DIR/evaluation.txt (ATE after SE(3) Umeyama
// alignment) and DIR/pose_errors.csv. Plots (tools/plot_odometry.py, python3-matplotlib):
// DIR/odometry.png (top and side view in metres, errors and per-scan time/status over time) and,
// for several methods, DIR/comparison.png; without matplotlib an SVG top view
// (trajectory_topview.svg) instead. Several methods separated by commas run one after the other
// and print their ATE side by side. Every write is checked (a full disk or an unwritable path is
// an error naming the path, exit 2); the odometry's input gates (lio/input_checks.h, config section
// `input:`) are reported in scans.log, evaluation.txt and the summary, and --max_imu_gap_error
// makes IMU gaps in the dataset files an error instead of a warning (docs/user-guide/bad-input.md).
// --save_map FILE.pcd|.ply writes the registered, deskewed points as a voxel-downsampled map and
// a top view FILE.png of it with the trajectory (apps/lio/map_accumulator.h, map_output.h).
// It says first which config it runs (or the built-in defaults), shows its progress on stderr
// (apps/lio/progress.h) and ends with the summary and the list of the files written (every writer
// registers its file with `files.Add(path, description)`, apps/lio/output_files.h).
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "common/command_line.h"
#include "common/preset_flags.h"
#include "ctlio/io/bag_sensor_suggestion.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/imu_specs.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "ctlio/solvers/lio/config_composition.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/calibration_output.h"
#include "lio/config_origin.h"
#include "lio/map_accumulator.h"
#include "lio/map_output.h"
#include "lio/output_files.h"
#include "lio/progress.h"
#include "lio/run_evaluation.h"
#include "lio/run_odometry.h"
#include "lio/run_outputs.h"
#include "lio/run_plots.h"

DEFINE_string(dataset, "", "Dataset folder, ROS 1 bag or ROS 2 bag (folder, .mcap, .db3)");
DEFINE_string(
    format, "",
    "newer_college | ctlio | kitti | rosbag | ros2 | sim (default: detect from the folder/file)");
DEFINE_string(lidar_topic, "",
              "rosbag: PointCloud2 topic (default: the only one, or the preset's)");
DEFINE_string(imu_topic, "", "rosbag: Imu topic (default: the only one, or the preset's)");
DEFINE_string(preset, "",
              "rosbag: newer_college_2020 | newer_college_2021 (default: recognised from topics)");
DEFINE_string(time_field, "", "Per-point time field (default: detected; 'none' = use the azimuth)");
DEFINE_string(time_unit, "", "Override the time field's unit: s | ms | us | ns");
DEFINE_string(time_reference, "", "Override: relative (to the message stamp) | absolute");
DEFINE_string(stamp_at, "", "Override: the message stamp is the scan start | end");
DEFINE_double(
    imu_accel_scale, 1.0,
    "ROS bags: factor from the accelerometer's unit to m/s² (9.80665 for IMUs reporting g); "
    "given explicitly it wins over input.accel_scale of --config");
DEFINE_bool(plot, true, "Write the plots (PNG with python3-matplotlib, else an SVG top view)");
DEFINE_string(python, "", "Python with matplotlib (default: python3, then /usr/bin/python3)");
DEFINE_double(trajectory_rate, 0.0,
              "Also write trajectory_dense.tum, the estimate at this rate [Hz] between the scan "
              "poses from the final estimates (Singer-LIO: GP interpolation; baseline: IMU "
              "propagation anchored at both states), and trajectory_dense_live.tum, the live "
              "(causal) one; 0 = off");
DEFINE_bool(
    write_bag, false,
    "Also write the estimate as nav_msgs/Odometry: trajectory.bag (ROS 2: trajectory_bag/)");
DEFINE_string(method, "singer_lio",
              "singer_lio | imu_input | lidar_gyro | lidar_only, or a comma-separated list");
DEFINE_string(config, "",
              "YAML config (data/sim_lio.yaml, data/newer_college_lio.yaml), or a comma-separated "
              "list whose later files win key by key (my.yaml,data/calibration.yaml); empty: the "
              "built-in defaults");
DEFINE_string(out, "", "Output folder (created); with several methods one subfolder per method");
DEFINE_int32(max_scans, 0, "Stop after this many scans (0 = all; negative is an error)");
DEFINE_double(max_imu_gap_error, 0.0,
              "Readers: an IMU gap longer than this [s] is an error naming file and line; 0 = off "
              "(the default: gaps are warnings, the odometry bridges them and flags the scans by "
              "init.max_imu_gap). Overrides input.max_imu_gap_error of --config");
DEFINE_bool(strict, false,
            "Every documented recovery of a reader or of the input gates (duplicate IMU samples "
            "dropped, unusable scans handed on, points dropped, scans retimed or skipped, IMU "
            "gaps, IMU samples rejected) is an error naming the defect; for pipelines that must "
            "not guess (docs/user-guide/bad-input.md). Given explicitly it wins over input.strict "
            "of --config");
DEFINE_int32(accel_reference_scans, 100,
             "Singer-LIO and imu_input: also run lidar_gyro (no accelerometer) over the first N "
             "scans as a reference the accelerometer cannot bend, and warn when a relabelling of "
             "its axes (swapped or flipped columns) explains that trajectory's accelerations "
             "clearly better than the axes as read (docs/user-guide/bad-input.md); the estimate "
             "is the same either way. 0 = off");
DEFINE_bool(progress, true, "Show progress on stderr");
DEFINE_double(play_rate, 0.0,
              "Give each scan to the odometry at its own time on the wall clock, sped up by this "
              "factor (1 = the sensor's pace, as rosbag play -r): the per-scan ms are then the "
              "latency from a sweep's arrival to its pose; 0 = back to back (the default)");
DEFINE_double(warmup_replay_adopt_after_s, 60.0,
              "The calibration warm-up replay runs on a second thread, adopted with the first "
              "scan this many seconds of data after its span or at the end of the input; < 0: "
              "inside the scan that reaches the span (the live output pauses for the replay)");
DEFINE_int32(frontend_threads, 1,
             "Threads of the lidar front end (association, range gate): lidar_frontend.threads "
             "of the config unless given; same results as one thread");
DEFINE_string(association, "",
              "Override lidar_frontend.association of the config: knn | voxel_plane");
DEFINE_string(sim_preset, "",
              "--format sim: preset none | newer_college | kitti (explicit --sim_* flags win)");
DEFINE_string(sim_sensor, "", "--format sim: sensor model (ctlio_simulate --sensor list)");
DEFINE_string(sim_regime, "fast", "--format sim: slow | medium | fast | walking | vehicle");
DEFINE_string(sim_world, "box", "--format sim: box|street|corridor|park|indoor|quad|town|office");
DEFINE_int32(sim_index, 0, "--format sim: sequence index within the regime");
DEFINE_double(sim_duration, 20.0, "--format sim: sequence length [s]");
DEFINE_int32(sim_firing_decimation, 1,
             "--format sim: keep every n-th firing (1 = full resolution)");
DEFINE_double(sim_lidar_rate, 10.0,
              "--format sim: lidar revolutions (= scans, = knots) per second [Hz]; the firings per "
              "revolution stay, so a faster rate spreads them over a shorter sweep");
DEFINE_int32(sim_beams, 128, "--format sim: lidar beams");
DEFINE_string(sim_imus, "",
              "--format sim: further IMUs, ';'-separated key=value lists (rate, xyz, rpy, offset, "
              "accel_noise, gyro_noise, accel_bias, gyro_bias, outage; apps/sim imu_specs.h), e.g. "
              "rate=400,xyz=0.3:0:0,offset=0.0013,accel_noise=0.04,gyro_noise=0.02");
DEFINE_bool(pose_covariance, false,
            "Each scan's pose covariance (window.pose_covariance) in trajectory_covariance.csv "
            "and --write_bag; with ground truth its NEES in evaluation.txt");
DEFINE_double(sim_imu_stamp_offset, 0.0,
              "--format sim: IMU 0's samples of the motion at t are stamped t - this [s] (the "
              "clock offset the online calibration should find; other IMUs: stamp_offset= in "
              "--sim_imus)");
DEFINE_bool(estimate_time_offset, false,
            "Estimate each IMU's clock offset online (calibration.estimate_time_offset)");
DEFINE_string(time_offset, "",
              "Comma-separated clock offset per IMU [s] (calibration.time_offset_s): the prior "
              "mean when estimated, else applied as given");
DEFINE_bool(calibration_keep_unobservable, true,
            "calibration.yaml keeps the start value of every calibration coordinate the data "
            "did not inform (calibration.write_max_sigma_*, write_max_unobservable_fraction); "
            "false writes the last estimates as they are");
DEFINE_string(sim_extrinsic_error, "",
              "--format sim: hand the odometry a NOMINAL extrinsic off the simulated one by "
              "<angle>deg[@ax:ay:az],<distance>m[@dx:dy:dz], e.g. 3deg,0.10m (axis and direction "
              "drawn per --sim_index when omitted; apps/sim extrinsic_error.h); the final "
              "extrinsic error is reported against the truth");
DEFINE_string(save_map, "",
              "Write the run's map to FILE.pcd or FILE.ply (binary, x y z float32): every scan's "
              "preprocessed points as the odometry inserted them into its own map, i.e. in the "
              "map frame and deskewed with that scan's live (causal) estimate, merged into "
              "--map_voxel_size voxels (the centroid of each), written at the end; and a top view "
              "FILE.png (python3-matplotlib) coloured by height with the trajectory. A relative "
              "FILE goes into the output folder (--out, or --out/<method> with several methods); "
              "an absolute one is used as is, with several methods with _<method> inserted "
              "before the extension. With a calibration warm-up replay the map starts at the "
              "replay, in the frame of trajectory.tum");
DEFINE_double(map_voxel_size, 0.2, "--save_map: voxel size [m]; one point per occupied voxel");
DEFINE_int64(map_max_points, 5000000,
             "--save_map: at most this many map points (the voxel table: 34-69 B per point, 1.5x "
             "that while it doubles; the default's bound is 302 MB); once reached, points in new "
             "voxels are dropped with a warning; 0 = no cap");
DEFINE_string(sim_imu_dropout, "",
              "--format sim: IMU outages start:length[,start:length...] in seconds since the "
              "sequence start (samples inside are absent), e.g. 5:1");

namespace {

using ::ctlio::apps::SplitList;

using namespace ctlio;

// A --sim_* flag applies unless a preset is chosen and the flag was not given explicitly.
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  return apps::Given(!FLAGS_sim_preset.empty() || !FLAGS_sim_sensor.empty(), flag, value);
}

// `input`: the config's reader options (input.max_imu_gap_error, input.accel_scale).
std::unique_ptr<io::DataSource> OpenSource(const lio::InputCheckOptions& input) {
  const int64_t gap_ns = std::llround(input.max_imu_gap_error * 1e9);
  if (FLAGS_format == "sim") {
    const sim::Preset preset = sim::ParsePreset(FLAGS_sim_preset);
    sim::SimOverrides given;
    if (auto r = Given("sim_regime", FLAGS_sim_regime)) given.regime = sim::ParseRegime(*r);
    if (auto w = Given("sim_world", FLAGS_sim_world)) given.world = sim::ParseWorld(*w);
    given.duration_s = Given("sim_duration", FLAGS_sim_duration);
    given.firing_decimation = Given("sim_firing_decimation", FLAGS_sim_firing_decimation);
    given.beams = Given("sim_beams", FLAGS_sim_beams);
    given.lidar_rate_hz = Given("sim_lidar_rate", FLAGS_sim_lidar_rate);
    if (!FLAGS_sim_sensor.empty()) given.sensor = FLAGS_sim_sensor;
    sim::SimConfig c = sim::PresetConfig(preset, FLAGS_sim_index, sim::kExperimentSeed, given);
    c.imu.outages = sim::ParseImuOutages(FLAGS_sim_imu_dropout);
    c.imu.stamp_offset_s = FLAGS_sim_imu_stamp_offset;
    c.extra_imus = sim::ParseImuSpecs(FLAGS_sim_imus, c.imu);
    const sim::ExtrinsicError extrinsic_error = sim::ParseExtrinsicError(FLAGS_sim_extrinsic_error);
    if (!extrinsic_error.IsZero()) {
      c.nominal_imu_from_lidar = sim::NominalExtrinsic(c.imu_from_lidar, extrinsic_error,
                                                       sim::kExperimentSeed, FLAGS_sim_index);
    }
    const sim::WorldKind world = given.world.value_or(sim::PresetWorld(preset));
    std::ostringstream name;
    name << "sim:"
         << (preset == sim::Preset::kNone ? "" : std::string(sim::PresetName(preset)) + ":")
         << (FLAGS_sim_sensor.empty() ? "" : FLAGS_sim_sensor + ":")
         << (world == sim::WorldKind::kBox ? "" : std::string(sim::WorldName(world)) + "/")
         << sim::RegimeName(given.regime.value_or(sim::PresetRegime(preset))) << "/"
         << FLAGS_sim_index;
    return std::make_unique<sim::SimulatedSource>(c, name.str());
  }
  if (FLAGS_dataset.empty()) throw std::runtime_error("--dataset is required (or --format sim)");
  if (FLAGS_format == "rosbag" || FLAGS_format == "ros2" ||
      (FLAGS_format.empty() && io::IsBagPath(FLAGS_dataset))) {
    io::BagOptions o;
    o.format = FLAGS_format;
    o.lidar_topic = FLAGS_lidar_topic;
    o.imu_topic = FLAGS_imu_topic;
    o.preset = FLAGS_preset;
    // --imu_accel_scale given explicitly wins over input.accel_scale of the config.
    o.accel_scale = gflags::GetCommandLineFlagInfoOrDie("imu_accel_scale").is_default
                        ? input.accel_scale
                        : FLAGS_imu_accel_scale;
    o.max_imu_gap_ns = gap_ns;
    o.time.field = FLAGS_time_field;
    if (!FLAGS_time_unit.empty()) o.time.unit = io::ParseTimeUnit(FLAGS_time_unit);
    if (!FLAGS_time_reference.empty())
      o.time.reference = io::ParseTimeReference(FLAGS_time_reference);
    if (!FLAGS_stamp_at.empty()) o.time.stamp_at = io::ParseStampAt(FLAGS_stamp_at);
    return std::make_unique<io::BagSource>(FLAGS_dataset, o);
  }
  if (!std::filesystem::is_directory(FLAGS_dataset)) {
    throw std::runtime_error(FLAGS_dataset + (std::filesystem::exists(FLAGS_dataset)
                                                  ? ": neither a dataset folder nor a ROS bag"
                                                  : ": dataset folder or bag does not exist"));
  }
  if (FLAGS_format.empty()) return io::OpenDataset(FLAGS_dataset, gap_ns);
  if (FLAGS_format == "newer_college") {
    io::NewerCollegeOptions options;
    options.max_imu_gap_error_ns = gap_ns;
    return std::make_unique<io::NewerCollegeReader>(FLAGS_dataset, options);
  }
  if (FLAGS_format == "ctlio") return std::make_unique<io::SimFolderReader>(FLAGS_dataset, gap_ns);
  if (FLAGS_format == "kitti") return std::make_unique<io::KittiReader>(FLAGS_dataset);
  throw std::runtime_error("unknown --format '" + FLAGS_format +
                           "' (newer_college, ctlio, kitti, rosbag, ros2, sim)");
}

#ifndef CTLIO_TOOLS_DIR
#define CTLIO_TOOLS_DIR "tools"
#endif

}  // namespace

constexpr char kUsage[] =
    "ctlio_odometry: lidar-inertial odometry (Singer-LIO and the IMU-as-input baseline) on a\n"
    "dataset folder, a ROS 1 bag or the built-in simulator; writes the trajectory, a per-scan log\n"
    "and, with ground truth, the ATE.\n"
    "\n"
    "  ctlio_odometry --dataset DIR|FILE.bag --config data/newer_college_lio.yaml --out /tmp/run\n"
    "  ctlio_odometry --format sim --sim_regime medium --sim_duration 5 \\\n"
    "      --config data/sim_lio.yaml --method singer_lio,imu_input --out /tmp/sim_run";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  try {
    // Counts and rates, before any work (docs/user-guide/bad-input.md).
    using ctlio::apps::RequireInRange;
    RequireInRange("frontend_threads", FLAGS_frontend_threads, 1, ctlio::apps::kMaxThreads);
    RequireInRange("trajectory_rate", FLAGS_trajectory_rate, 0.0, 1e4, " Hz (0 = off)");
    RequireInRange("play_rate", FLAGS_play_rate, 0.0, 1e6, " (0 = back to back)");
    RequireInRange("accel_reference_scans", FLAGS_accel_reference_scans, 0, 1'000'000,
                   " (0 = off)");
    RequireInRange("max_imu_gap_error", FLAGS_max_imu_gap_error, 0.0, 1e6, " s (0 = off)");
    RequireInRange("imu_accel_scale", FLAGS_imu_accel_scale, 1e-6, 1e6,
                   " (9.80665 for an IMU reporting g)");
    RequireInRange("sim_index", FLAGS_sim_index, 0, 1'000'000);
    RequireInRange("sim_duration", FLAGS_sim_duration, 0.1, 3600.0, " s");
    RequireInRange("sim_beams", FLAGS_sim_beams, 1, 4096);
    RequireInRange("sim_firing_decimation", FLAGS_sim_firing_decimation, 1, 1'000'000);
    RequireInRange("sim_lidar_rate", FLAGS_sim_lidar_rate, 0.1, 1000.0, " Hz");
    const std::vector<std::string> methods = SplitList(FLAGS_method);
    if (methods.empty()) throw std::runtime_error("--method is empty");
    lio::OdometryConfig base;
    // An `extrinsic:` written in the config wins over the dataset's (precedence:
    // docs/user-guide/configuration.md).
    bool config_extrinsic = false;
    if (!FLAGS_config.empty()) {
      const YAML::Node root = lio::LoadOdometryYaml(FLAGS_config);
      config_extrinsic = root["extrinsic"].IsDefined();
      base = lio::OdometryConfigFromYaml(root, lio::SplitConfigList(FLAGS_config).back());
    }
    std::printf("config: %s\n", lioapp::DescribeConfig(FLAGS_config).c_str());
    std::fflush(stdout);
    // The readers' IMU gap limit (input.max_imu_gap_error): the flag wins over the config.
    const bool gap_flag = !gflags::GetCommandLineFlagInfoOrDie("max_imu_gap_error").is_default;
    if (FLAGS_out.empty()) throw std::runtime_error("--out is required");
    if (FLAGS_max_scans < 0) throw std::runtime_error("--max_scans must be >= 0 (0 = all)");
    if (!FLAGS_save_map.empty()) {  // before the run, not after an hour of it
      lioapp::CheckMapFlags(FLAGS_save_map, FLAGS_map_voxel_size, FLAGS_map_max_points);
    }
    std::vector<lioapp::RunSummary> runs;
    std::vector<std::string> folders;
    std::vector<std::vector<io::StampedPose>> truths;
    lioapp::OutputFiles files;  // every file written, listed at the end
    const auto run_start = std::filesystem::file_time_type::clock::now();
    for (const std::string& m : methods) {
      lio::OdometryConfig config = base.ForMethod(lio::ParseLioMethod(m));
      if (gap_flag) config.input.max_imu_gap_error = FLAGS_max_imu_gap_error;
      if (FLAGS_pose_covariance) config.pose_covariance = true;
      if (!gflags::GetCommandLineFlagInfoOrDie("frontend_threads").is_default) {
        config.frontend.threads = FLAGS_frontend_threads;
      }
      if (!FLAGS_association.empty()) config.frontend.association = FLAGS_association;
      if (FLAGS_estimate_time_offset) config.calibration.estimate_time_offset = true;
      if (!FLAGS_time_offset.empty()) {
        config.calibration.time_offset_s.clear();
        for (const std::string& d : SplitList(FLAGS_time_offset)) {
          size_t used = 0;
          double v = NAN;
          try {
            v = std::stod(d, &used);
          } catch (const std::exception&) {
          }
          if (used != d.size() || !std::isfinite(v)) {
            throw std::runtime_error("--time_offset: '" + d + "' is not a number of seconds");
          }
          config.calibration.time_offset_s.push_back(v);
        }
      }
      config.Validate();
      // Before the readers read anything; --strict given explicitly wins over input.strict.
      ctlio::io::WarningLimiter::SetStrict(gflags::GetCommandLineFlagInfoOrDie("strict").is_default
                                               ? config.input.strict
                                               : FLAGS_strict);
      auto source = OpenSource(config.input);
      if (FLAGS_config.empty() && m == methods.front()) io::LogSensorSuggestion(*source);
      const std::string out = methods.size() > 1 ? FLAGS_out + "/" + m : FLAGS_out;
      std::filesystem::create_directories(out);
      lioapp::RunOptions options;
      options.max_scans = static_cast<size_t>(FLAGS_max_scans);
      options.extrinsic_from_config = config_extrinsic;
      options.trajectory_rate_hz = FLAGS_trajectory_rate;
      options.play_rate = FLAGS_play_rate;
      options.replay_adopt_after_s = FLAGS_warmup_replay_adopt_after_s;
      options.accel_reference_scans = static_cast<size_t>(FLAGS_accel_reference_scans);
      options.accel_reference_config = base.ForMethod(lio::LioMethod::kLidarGyro);
      lioapp::ProgressReporter progress(std::cerr, lioapp::ProgressReporter::IsTerminal(2));
      progress.SetEventLimit(20, "scans.log has every scan's status and message");
      if (FLAGS_progress) {
        options.progress = [&](size_t done, size_t total, const lio::ScanResult& r) {
          char line[160];
          std::snprintf(line, sizeof(line), "[%s] scan %zu/%zu  %-12s %5d associations  %6.1f ms",
                        m.c_str(), done, total, lio::ScanStatusName(r.status), r.associations,
                        r.milliseconds);
          progress.Update(done, total, line);
          if (r.status == lio::ScanStatus::kFailed || r.status == lio::ScanStatus::kDegenerate ||
              r.status == lio::ScanStatus::kImuGap || r.status == lio::ScanStatus::kSuspect) {
            std::snprintf(line, sizeof(line), "  %s at t = %.3f s: ", lio::ScanStatusName(r.status),
                          1e-9 * double(r.t_ns));
            progress.Event(line + r.message);
          }
        };
      }
      std::optional<lioapp::MapAccumulator> map;
      if (!FLAGS_save_map.empty()) {
        map.emplace(FLAGS_map_voxel_size, static_cast<size_t>(FLAGS_map_max_points));
        options.map_points = [&map, &m](const lio::ScanResult& r, const std::vector<Vec3>& points) {
          if (r.revised_scans > 0) {
            LOG(INFO) << m << ": the map starts over in the frame of the calibration warm-up "
                      << "replay (" << map->size() << " points of the live warm-up dropped)";
            map->Clear();
          }
          const size_t dropped = map->dropped_points();
          map->Add(points);
          if (dropped == 0 && map->dropped_points() > 0) {
            LOG(WARNING) << m << ": the map reached --map_max_points " << map->max_points()
                         << ": points in new voxels are dropped from here on";
          }
        };
      }
      lioapp::RunSummary run = lioapp::RunOdometry(*source, config, options);
      // The calibration.yaml values, also summarised in evaluation.txt.
      const auto recommended = lioapp::RecommendCalibration(run, config.calibration,
                                                            FLAGS_calibration_keep_unobservable);
      if (FLAGS_progress) progress.Finish();
      io::WriteTum(out + "/trajectory.tum", run.trajectory);
      files.Add(out + "/trajectory.tum",
                "T_world_lidar at every scan end (TUM: t x y z qx qy qz qw)");
      if (FLAGS_pose_covariance) lioapp::WriteTrajectoryCovariance(out, run.scans, &files);
      if (!run.dense.empty()) {
        io::WriteTum(out + "/trajectory_dense.tum", run.dense);
        files.Add(
            out + "/trajectory_dense.tum",
            "the continuous-time estimate at --trajectory_rate from the final estimates (TUM)");
      }
      if (!run.dense_live.empty()) {
        io::WriteTum(out + "/trajectory_dense_live.tum", run.dense_live);
        files.Add(out + "/trajectory_dense_live.tum",
                  "the same rate as returned live, scan by scan (causal; TUM)");
      }
      lioapp::WriteScanLog(out + "/scans.log", run);
      files.Add(out + "/scans.log", "one line per scan: status, residuals, times [ms], degeneracy");
      const std::string ev_path = out + "/evaluation.txt";
      std::ofstream ev = io::OpenForWriting(ev_path);
      const std::optional<std::vector<io::StampedPose>> truth = source->GroundTruth();
      lioapp::WriteRunEvaluation(run, recommended, truth ? &*truth : nullptr, ev);
      if (run.ate) {
        io::WriteTum(out + "/ground_truth.tum", *truth);
        files.Add(out + "/ground_truth.tum", "the source's ground truth (TUM)");
        lioapp::WritePoseErrors(out + "/pose_errors.csv", run.trajectory, *truth,
                                run.ate->alignment);
        files.Add(out + "/pose_errors.csv", "per-pose position [m] and rotation [deg] error");
        truths.push_back(*truth);
      } else {
        truths.emplace_back();
      }
      if (config.calibration.any()) {
        lioapp::WriteCalibrationOutputs(out, run, recommended, &files, ev);
      }
      if (FLAGS_write_bag) {
        const auto [bag, what] =
            io::WriteEstimateBag(out, run.source, run.trajectory, lioapp::RosPoseCovariances(run));
        files.Add(bag, what);
      }
      if (map) {
        const std::string map_path = lioapp::MapPath(FLAGS_save_map, out, m, methods.size() > 1);
        lioapp::WriteMap(*map, map_path, out + "/trajectory.tum", FLAGS_plot,
                         FLAGS_plot ? lioapp::PythonWithMatplotlib(FLAGS_python) : "",
                         CTLIO_TOOLS_DIR, m + " on " + run.source, ev);
        files.Add(map_path, "the registered, deskewed map (--save_map), map frame, x y z float32");
        const std::string map_png = lioapp::MapPicturePath(map_path);
        std::error_code no_png;
        if (FLAGS_plot && std::filesystem::exists(map_png, no_png)) {
          files.Add(map_png, "plot: top view of the map with the trajectory");
        }
      }
      folders.push_back(out);
      if (!run.first_failure.empty()) ev << "first_failure \"" << run.first_failure << "\"\n";
      io::CloseChecked(ev, ev_path);
      files.Add(ev_path, "counts, times [ms], ATE [m] of the run (one `key value` per line)");
      runs.push_back(std::move(run));
    }
    const std::string python = FLAGS_plot ? lioapp::PythonWithMatplotlib(FLAGS_python) : "";
    if (FLAGS_plot && !lioapp::PlotRuns(python, CTLIO_TOOLS_DIR, FLAGS_out, folders)) {
      std::fprintf(stderr, "plots: no python3 with matplotlib, SVG top view instead\n");
      for (size_t k = 0; k < runs.size(); ++k) {
        if (!runs[k].ate) continue;
        char title[240];
        std::snprintf(title, sizeof(title), "%s on %s: ATE %.2f cm", runs[k].method.c_str(),
                      runs[k].source.c_str(), 100.0 * runs[k].ate->rmse);
        lioapp::WriteTopViewSvg(folders[k] + "/trajectory_topview.svg", runs[k].trajectory,
                                truths[k], runs[k].ate->alignment, title);
      }
    }
    lioapp::ListPlots(FLAGS_out, folders, run_start, &files);
    lioapp::PrintRunTables(runs);
    std::printf("\n");
    std::ostringstream listing;
    files.Print(listing);
    std::printf("%s", listing.str().c_str());
    int bad = 0;
    for (const auto& r : runs) bad += r.failure ? 1 : 0;
    return bad ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_odometry: %s\n", e.what());
    return 2;
  }
}
