// ctlio_experiment: the paper's Table II (SPEC §6). Simulates the regimes × sequences on the fly
// (nothing large is written), runs every method on every sequence in parallel over the cores,
// and writes OUT/table.md (overall RMSE ATE per regime and method over all sequences of the
// regime, failures, median and p95 ms per scan), OUT/results.csv (one line per run) and
// OUT/table2.svg (bar plot of the overall RMSE ATE per regime and method; no plotting dependency).
//
//   ctlio_experiment --out /tmp/table2                       # the full experiment (hours)
//   ctlio_experiment --out /tmp/t2 --sequences 3 --duration 5 --beams 32 --firing_decimation 4
//   ctlio_experiment --out /tmp/nc --sim_preset newer_college --config data/newer_college_lio.yaml
//                    --methods singer_lio,imu_input --sequences 5 --duration 60
//
// The reduced flags are for quick runs: the table records them in its header so that a reduced
// table is never mistaken for the full one.
//
// IMU dropout: --imu_outage 0.2,0.5,1,2 adds one scenario per length, an outage of that length
// centred on the sequence midpoint (the "none" scenario is kept unless --nominal=false).
//
// Several IMUs: --imus SPEC adds IMUs 1, 2, ... to every sequence (apps/sim imu_specs.h; the
// outages of --imu_outage apply to IMU 0). --pose_covariance also computes every scan's pose
// covariance and writes the NEES per run into OUT/nees.csv and a consistency table into
// OUT/table.md.
//
// Split jobs: each job writes OUT/results.csv (one line per run) and OUT/settings.txt; run
// subsets (--regimes, --methods, --first_sequence, --sequences) as separate jobs and pool them:
//   ctlio_experiment --merge DIR1,DIR2,... --out DIR
// writes the table of all their runs (the settings of the jobs must be equal).
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>
#include <tuple>

#include "common/command_line.h"
#include "common/preset_flags.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/imu_specs.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "ctlio/sim/sensor_models.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/calibration_output.h"
#include "lio/config_origin.h"
#include "lio/experiment_outputs.h"
#include "lio/experiment_results.h"
#include "lio/output_files.h"
#include "lio/run_odometry.h"

DEFINE_string(out, "", "Output folder (required)");
DEFINE_string(config, "",
              "YAML config, or a comma-separated list whose later files win key by key "
              "(default: data/sim_lio.yaml of the source tree, data/newer_college_lio.yaml with "
              "--sim_preset newer_college)");
DEFINE_string(regimes, "slow,medium,fast", "Comma-separated regimes (also walking, vehicle)");
DEFINE_string(sim_sensor, "",
              "Sensor model os0_128 | os1_64 | os1_128 | vlp16 | hdl32e | pandar_xt32 | mid360 | "
              "avia (ctlio_simulate --sensor list; sets lidar, IMU and extrinsic; default config "
              "data/sensors/<sensor>.yaml)");
DEFINE_string(sim_sensor_effects, "auto",
              "The simulated lidar unit's effects (ctlio_simulate --sensor_effects): auto (the "
              "preset's family; --sim_sensor's family in quad, town and office; none otherwise) | "
              "off | ouster | hdl64 | velodyne | hesai | livox");
DEFINE_string(
    sim_preset, "",
    "Recording preset: none | newer_college | kitti (sets world, regime, sensors, IMU, duration; "
    "explicit --world/--regimes/--duration/--beams/--firing_decimation/--body_centric "
    "win)");
DEFINE_string(world, "box",
              "Simulated world: box | street | corridor | park | indoor | quad | town | office");
DEFINE_string(methods, "singer_lio,imu_input,lidar_gyro,lidar_only", "Comma-separated methods");
DEFINE_int32(sequences, 20, "Sequences per regime (the paper: 20)");
DEFINE_int32(first_sequence, 0, "Index of the first sequence");
DEFINE_double(duration, 20.0, "Sequence length [s] (the paper: 20)");
DEFINE_int32(beams, 128, "Lidar beams (the paper: 128)");
DEFINE_int32(firing_decimation, 1, "Keep every n-th lidar firing (1 = full resolution)");
DEFINE_double(
    lidar_rate, 10.0,
    "Lidar revolutions (= scans, = knots) per second [Hz] (the firings per revolution stay)");
DEFINE_int32(threads, 0, "Parallel runs (0 = number of cores)");
DEFINE_bool(body_centric, false, "Simulate the paper's body-centric accelerometer model");
DEFINE_double(failure_ate, 1.0, "A run whose ATE exceeds this [m] counts as a failure");
DEFINE_string(imu_outage, "",
              "Comma-separated IMU outage lengths [s]: one scenario per length, the outage "
              "centred on the sequence midpoint");
DEFINE_bool(nominal, true, "With --imu_outage: also run the scenario without outage");
DEFINE_string(imus, "",
              "Further IMUs in every sequence: ';'-separated key=value lists (rate, xyz, rpy, "
              "offset, accel_noise, gyro_noise, accel_bias, gyro_bias, outage; imu_specs.h)");
DEFINE_double(imu_stamp_offset, 0.0,
              "IMU 0's samples of the motion at t are stamped t - this [s] (the simulated clock "
              "offset; other IMUs: stamp_offset= in --imus)");
DEFINE_bool(estimate_time_offset, false,
            "Estimate each IMU's clock offset online (calibration.estimate_time_offset); the "
            "final estimates, sigmas and errors per run go to OUT/calibration.csv");
DEFINE_string(time_offset, "",
              "Comma-separated clock offset per IMU [s] (calibration.time_offset_s): the prior "
              "mean when estimated, else applied as given");
DEFINE_string(extrinsic_error, "",
              "Hand every run a NOMINAL lidar->IMU extrinsic off the simulated one by "
              "<angle>deg[@ax:ay:az],<distance>m[@dx:dy:dz], e.g. 3deg,0.10m (axis and direction "
              "drawn per sequence when omitted; apps/sim extrinsic_error.h); with it or with "
              "calibration.estimate_extrinsic, OUT/extrinsic.csv has every run's extrinsic error");
DEFINE_bool(pose_covariance, false,
            "Pose covariance per scan and its NEES against the truth (OUT/nees.csv)");
DEFINE_string(merge, "",
              "Comma-separated output folders of earlier jobs: pool their results.csv into the "
              "table of --out instead of running");

namespace {

using ::ctlio::apps::SplitList;

using namespace ctlio;

lioapp::OutputFiles written;  // every file the run writes, listed at its end

using Job = lioapp::ExperimentJob;

// The settings that must be equal for runs to be pooled, one "key value" per line.
std::string SettingsText(const std::string& config_path, const std::string& preset,
                         const std::string& world, const ctlio::sim::SimConfig& shared,
                         const std::string& sensor_effects) {
  std::ostringstream s;
  s << "preset " << preset << "\nworld " << world << "\nduration_s " << shared.duration_s
    << "\nbeams " << shared.lidar.beams << "\nfiring_decimation " << shared.lidar.firing_decimation
    << "\nimu_model " << (shared.imu.body_centric ? "body-centric" : "exact-specific-force")
    << "\nconfig " << std::filesystem::path(config_path).filename().string() << "\nfailure_ate_m "
    << FLAGS_failure_ate << "\n";
  // Only when set, so that single-IMU settings (and merges with earlier jobs) stay as they were.
  if (!FLAGS_imus.empty()) s << "imus " << FLAGS_imus << "\n";
  // The scoreboard labels a cell by it (apps/lio/scoreboard.h).
  if (!FLAGS_sim_sensor.empty()) s << "sensor " << FLAGS_sim_sensor << "\n";
  if (!FLAGS_extrinsic_error.empty()) s << "extrinsic_error " << FLAGS_extrinsic_error << "\n";
  if (shared.lidar.rate_hz != 10.0) s << "lidar_rate_hz " << shared.lidar.rate_hz << "\n";
  if (sensor_effects != "off") s << "sensor_effects " << sensor_effects << "\n";
  return s.str();
}

std::string ReadText(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open (not an experiment output folder?)");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// --merge: pool the results of earlier jobs with equal settings.
void Merge() {
  std::string settings;
  std::vector<lioapp::RunRow> rows;
  std::set<std::tuple<std::string, int, std::string, std::string>> seen;
  const auto dirs = SplitList(FLAGS_merge);
  for (const std::string& dir : dirs) {
    const std::string s = ReadText(dir + "/settings.txt");
    if (settings.empty()) settings = s;
    if (s != settings) {
      throw std::runtime_error(dir + "/settings.txt: settings differ from " + dirs.front() +
                               "/settings.txt; runs with different settings cannot be pooled");
    }
    for (const auto& r : lioapp::ReadResultsCsv(dir + "/results.csv")) {
      if (!seen.insert({r.regime, r.sequence, r.method, r.scenario}).second) {
        throw std::runtime_error(dir + "/results.csv: run " + r.regime + "/" +
                                 std::to_string(r.sequence) + " " + r.method + " " + r.scenario +
                                 " appears in more than one job");
      }
      rows.push_back(r);
    }
  }
  if (rows.empty()) throw std::runtime_error("--merge: no runs in " + FLAGS_merge);
  std::filesystem::create_directories(FLAGS_out);
  io::WriteTextFile(FLAGS_out + "/settings.txt", settings);
  written.Add(FLAGS_out + "/settings.txt", "the settings runs must share to be merged");
  lioapp::WriteResultsCsv(FLAGS_out + "/results.csv", rows);
  written.Add(FLAGS_out + "/results.csv", "one line per run: ATE [m], scan counts, ms (CSV)");
  lioapp::WriteTable(FLAGS_out, settings, rows,
                     "Merged from " + std::to_string(dirs.size()) + " jobs (" + FLAGS_merge + ").",
                     &written);
}

}  // namespace

// A flag applies unless a preset is chosen and the flag was not given explicitly.
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  return ctlio::apps::Given(!FLAGS_sim_preset.empty() || !FLAGS_sim_sensor.empty(), flag, value);
}

constexpr char kUsage[] =
    "ctlio_experiment: the paper's Table II: simulates regimes x sequences and runs every\n"
    "method on each, in parallel; writes OUT/table.md, results.csv and table2.svg.\n"
    "\n"
    "  ctlio_experiment --out /tmp/t2 --sequences 3 --duration 5 --beams 32 --firing_decimation 4\n"
    "  ctlio_experiment --out /tmp/table2                    # the full experiment (hours)\n"
    "  ctlio_experiment --merge /tmp/a,/tmp/b --out /tmp/ab  # pool split jobs";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  try {
    // Counts and rates, before any work (docs/user-guide/bad-input.md): a huge --threads used to
    // abort inside thread creation.
    using ctlio::apps::RequireInRange;
    RequireInRange("threads", FLAGS_threads, 0, ctlio::apps::kMaxThreads, " (0 = number of cores)");
    RequireInRange("sequences", FLAGS_sequences, 1, 100'000);
    RequireInRange("first_sequence", FLAGS_first_sequence, 0, 1'000'000);
    RequireInRange("duration", FLAGS_duration, 0.1, 3600.0, " s");
    RequireInRange("beams", FLAGS_beams, 1, 4096);
    RequireInRange("firing_decimation", FLAGS_firing_decimation, 1, 1'000'000);
    RequireInRange("lidar_rate", FLAGS_lidar_rate, 0.1, 1000.0, " Hz");
    if (FLAGS_out.empty()) throw std::runtime_error("--out is required");
    if (!FLAGS_merge.empty()) {
      Merge();
      written.Print(std::cout);
      return 0;
    }
    std::filesystem::create_directories(FLAGS_out);
    if (!FLAGS_sim_sensor.empty()) sim::FindSensorModel(FLAGS_sim_sensor);  // a clear error
    // Default configuration: the one written for the simulated sensors.
    const std::string config_path =
        !FLAGS_config.empty() ? FLAGS_config
        : !FLAGS_sim_sensor.empty()
            ? std::string(CTLIO_SOURCE_DIR) + "/data/sensors/" + FLAGS_sim_sensor + ".yaml"
        : FLAGS_sim_preset == "newer_college"
            ? std::string(CTLIO_SOURCE_DIR) + "/data/newer_college_lio.yaml"
            : std::string(CTLIO_SOURCE_DIR) + "/data/sim_lio.yaml";
    const lio::OdometryConfig base = lio::LoadOdometryConfig(config_path);
    std::printf("config: %s%s\n", lioapp::DescribeConfig(config_path).c_str(),
                FLAGS_config.empty() ? " (the default; --config to choose another)" : "");
    std::fflush(stdout);
    const sim::Preset preset = sim::ParsePreset(FLAGS_sim_preset);
    sim::SimOverrides given;  // the settings every sequence shares (regime: per job)
    if (auto w = Given("world", FLAGS_world)) given.world = sim::ParseWorld(*w);
    given.duration_s = Given("duration", FLAGS_duration);
    given.beams = Given("beams", FLAGS_beams);
    given.firing_decimation = Given("firing_decimation", FLAGS_firing_decimation);
    given.lidar_rate_hz = Given("lidar_rate", FLAGS_lidar_rate);
    given.body_centric = Given("body_centric", FLAGS_body_centric);
    if (!FLAGS_sim_sensor.empty()) given.sensor = FLAGS_sim_sensor;
    if (FLAGS_sim_sensor_effects != "auto") given.sensor_effects = FLAGS_sim_sensor_effects;
    const std::string world_name = sim::WorldName(given.world.value_or(sim::PresetWorld(preset)));
    const auto regimes = SplitList(
        Given("regimes", FLAGS_regimes).value_or(sim::RegimeName(sim::PresetRegime(preset))));
    const auto methods = SplitList(FLAGS_methods);
    for (const auto& r : regimes) sim::ParseRegime(r);
    const sim::SimConfig shared = sim::PresetConfig(preset, 0, sim::kExperimentSeed, given);
    for (const auto& m : methods) lio::ParseLioMethod(m);
    const sim::ExtrinsicError extrinsic_error = sim::ParseExtrinsicError(FLAGS_extrinsic_error);
    // Scenarios: (name, outage length); the nominal one first.
    std::vector<std::pair<std::string, double>> scenarios;
    if (FLAGS_imu_outage.empty() || FLAGS_nominal) scenarios.push_back({"none", 0.0});
    for (const auto& text : SplitList(FLAGS_imu_outage)) {
      size_t used = 0;
      double length = NAN;
      try {
        length = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != text.size() || !(length > 0 && length < FLAGS_duration)) {
        throw std::runtime_error(
            "--imu_outage: length '" + text +
            "' must be a number of seconds, positive and shorter than --duration");
      }
      std::ostringstream name;
      name << "outage_" << length << "s";
      scenarios.push_back({name.str(), length});
    }

    std::vector<Job> jobs;
    for (const auto& r : regimes) {
      for (int i = FLAGS_first_sequence; i < FLAGS_first_sequence + FLAGS_sequences; ++i) {
        for (const auto& [scenario, length] : scenarios) {
          for (const auto& m : methods) jobs.push_back({r, i, m, scenario, length});
        }
      }
    }
    // Slow jobs first (the last regime, fast, with all methods) so that the tail of the
    // schedule is short; the results keep the order above.
    std::vector<size_t> order(jobs.size());
    for (size_t j = 0; j < jobs.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return std::find(regimes.begin(), regimes.end(), jobs[a].regime) >
             std::find(regimes.begin(), regimes.end(), jobs[b].regime);
    });
    const int threads =
        FLAGS_threads > 0 ? FLAGS_threads : std::max(1u, std::thread::hardware_concurrency());
    std::atomic<size_t> next{0};
    std::atomic<size_t> finished{0};
    std::mutex print;
    const auto start = std::chrono::steady_clock::now();
    auto worker = [&]() {
      for (size_t k = next++; k < jobs.size(); k = next++) {
        Job& job = jobs[order[k]];
        try {
          sim::SimOverrides job_given = given;
          job_given.regime = sim::ParseRegime(job.regime);
          sim::SimConfig c = sim::PresetConfig(preset, job.index, sim::kExperimentSeed, job_given);
          if (job.outage_s > 0) {
            c.imu.outages.push_back({0.5 * (c.duration_s - job.outage_s), job.outage_s});
          }
          c.imu.stamp_offset_s = FLAGS_imu_stamp_offset;
          c.extra_imus = sim::ParseImuSpecs(FLAGS_imus, c.imu);
          if (!extrinsic_error.IsZero()) {
            c.nominal_imu_from_lidar = sim::NominalExtrinsic(c.imu_from_lidar, extrinsic_error,
                                                             sim::kExperimentSeed, job.index);
          }
          sim::SimulatedSource source(c, "sim:" + job.regime + "/" + std::to_string(job.index));
          lio::OdometryConfig config = base.ForMethod(lio::ParseLioMethod(job.method));
          if (FLAGS_pose_covariance) config.pose_covariance = true;
          if (FLAGS_estimate_time_offset) config.calibration.estimate_time_offset = true;
          if (!FLAGS_time_offset.empty()) {
            config.calibration.time_offset_s.clear();
            std::stringstream list(FLAGS_time_offset);
            for (std::string d; std::getline(list, d, ',');) {
              config.calibration.time_offset_s.push_back(std::stod(d));
            }
          }
          job.run = lioapp::RunOdometry(source, config, {}, FLAGS_failure_ate);
          job.done = true;
        } catch (const std::exception& e) {
          job.error = e.what();
        }
        const size_t n = ++finished;
        std::lock_guard<std::mutex> lock(print);
        const double el =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "[%zu/%zu %6.0f s] %-6s %2d %-10s %-12s ", n, jobs.size(), el,
                     job.regime.c_str(), job.index, job.method.c_str(), job.scenario.c_str());
        if (!job.done) {
          std::fprintf(stderr, "ERROR %s\n", job.error.c_str());
        } else {
          std::fprintf(stderr, "ATE %.4f m  failed scans %d  gap scans %d  median %.1f ms%s\n",
                       job.run.ate ? job.run.ate->rmse : NAN, job.run.failed, job.run.imu_gaps,
                       job.run.median_ms, job.run.failure ? "  FAILURE" : "");
        }
      }
    };
    std::vector<std::thread> pool;
    try {
      for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    } catch (const std::system_error& e) {
      // Let the started workers finish the jobs; the message says why there are fewer.
      std::fprintf(stderr, "warning: started %zu of %d threads (%s); running on those\n",
                   pool.size(), threads, e.what());
      if (pool.empty()) throw std::runtime_error(std::string("cannot start a thread: ") + e.what());
    }
    for (auto& t : pool) t.join();

    std::vector<lioapp::RunRow> rows;
    for (const Job& j : jobs) {
      lioapp::RunRow r;
      r.regime = j.regime;
      r.sequence = j.index;
      r.method = j.method;
      r.scenario = j.scenario;
      r.ate_rmse_m = j.done && j.run.ate ? j.run.ate->rmse : NAN;
      r.ate_pairs = j.done && j.run.ate ? j.run.ate->pairs : 0;
      r.failed_scans = j.run.failed;
      r.degenerate_scans = j.run.degenerate;
      r.imu_gap_scans = j.run.imu_gaps;
      r.failure = !j.done || j.run.failure;
      r.median_ms = j.run.median_ms;
      r.p95_ms = j.run.p95_ms;
      r.max_ms = j.run.max_ms;
      r.median_cpu_ms = j.run.median_cpu_ms;
      r.p95_cpu_ms = j.run.p95_cpu_ms;
      r.drift_m_per_100m = j.done && j.run.drift_per_100m ? *j.run.drift_per_100m : NAN;
      r.scans = static_cast<int>(j.run.scans.size());
      r.degenerate_direction_scans = j.run.degenerate_direction_scans;
      r.error = j.error;
      rows.push_back(r);
    }
    const std::string settings = SettingsText(config_path, sim::PresetName(preset), world_name,
                                              shared, sim::PresetSensorEffects(preset, given));
    io::WriteTextFile(FLAGS_out + "/settings.txt", settings);
    written.Add(FLAGS_out + "/settings.txt", "the settings runs must share to be merged");
    lioapp::WriteResultsCsv(FLAGS_out + "/results.csv", rows);
    written.Add(FLAGS_out + "/results.csv", "one line per run: ATE [m], scan counts, ms (CSV)");
    if (FLAGS_pose_covariance) lioapp::WriteNees(FLAGS_out, jobs, &written);
    if (FLAGS_estimate_time_offset || base.calibration.estimate_time_offset) {
      lioapp::WriteCalibration(FLAGS_out, jobs, &written);
    }
    lioapp::WriteExtrinsicErrors(FLAGS_out, jobs, &written);
    lioapp::WriteObservability(FLAGS_out, jobs, &written);
    const double el =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ostringstream provenance;
    provenance << "Wall time " << el << " s on " << threads << " threads.";
    lioapp::WriteTable(FLAGS_out, settings, rows, provenance.str(), &written);
    std::printf("\n");
    std::fflush(stdout);
    written.Print(std::cout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_experiment: %s\n", e.what());
    return 2;
  }
}
