// ctlio_odometry: lidar-inertial odometry on a dataset folder or on the in-memory simulator.
//
//   ctlio_odometry --dataset DIR --format newer_college|ctlio|kitti
//                  --method singer_lio|imu_input|lidar_gyro|lidar_only --config FILE --out DIR
//   ctlio_odometry --format sim --sim_regime fast --sim_index 0 [--sim_duration 5 ...] ...
//   ctlio_odometry --format sim --sim_preset newer_college --sim_index 0 \
//                  --config data/newer_college_lio.yaml --out DIR
//
// Writes DIR/trajectory.tum (T_world_lidar at every scan end, TUM `t x y z qx qy qz qw`),
// DIR/scans.log (one line per scan: status, residual counts, iterations, time) and, when the
// source has ground truth, DIR/ground_truth.tum and DIR/evaluation.txt (ATE after SE(3) Umeyama
// alignment) with DIR/trajectory_topview.svg (estimate over ground truth). Several methods
// separated by commas run one after the other and print their ATE side by side.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

DEFINE_string(dataset, "", "Dataset folder (not used with --format sim)");
DEFINE_string(format, "", "newer_college | ctlio | kitti | sim (default: detect from the folder)");
DEFINE_string(method, "singer_lio",
              "singer_lio | imu_input | lidar_gyro | lidar_only, or a comma-separated list");
DEFINE_string(config, "", "YAML config (data/sim_lio.yaml, data/newer_college_lio.yaml)");
DEFINE_string(out, "", "Output folder (created); with several methods one subfolder per method");
DEFINE_int32(max_scans, 0, "Stop after this many scans (0 = all)");
DEFINE_bool(progress, true, "Show progress on stderr");
DEFINE_string(sim_preset, "",
              "--format sim: recording preset none | newer_college (explicit --sim_* flags win)");
DEFINE_string(sim_regime, "fast", "--format sim: slow | medium | fast | walking | vehicle");
DEFINE_string(sim_world, "box", "--format sim: box | street | corridor | park | indoor");
DEFINE_int32(sim_index, 0, "--format sim: sequence index within the regime");
DEFINE_double(sim_duration, 20.0, "--format sim: sequence length [s]");
DEFINE_int32(sim_firing_decimation, 1, "--format sim: keep every n-th firing");
DEFINE_int32(sim_beams, 128, "--format sim: lidar beams");

namespace {

using namespace ctlio;

// A --sim_* flag's value when it should apply: always without a preset, only if given
// explicitly with one (the preset's value stands otherwise).
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  if (FLAGS_sim_preset.empty() || !gflags::GetCommandLineFlagInfoOrDie(flag).is_default) {
    return value;
  }
  return std::nullopt;
}

std::unique_ptr<io::DataSource> OpenSource() {
  if (FLAGS_format == "sim") {
    const sim::Preset preset = sim::ParsePreset(FLAGS_sim_preset);
    sim::SimOverrides given;
    if (auto r = Given("sim_regime", FLAGS_sim_regime)) given.regime = sim::ParseRegime(*r);
    if (auto w = Given("sim_world", FLAGS_sim_world)) given.world = sim::ParseWorld(*w);
    given.duration_s = Given("sim_duration", FLAGS_sim_duration);
    given.firing_decimation = Given("sim_firing_decimation", FLAGS_sim_firing_decimation);
    given.beams = Given("sim_beams", FLAGS_sim_beams);
    const sim::SimConfig c =
        sim::PresetConfig(preset, FLAGS_sim_index, sim::kExperimentSeed, given);
    const sim::WorldKind world = given.world.value_or(sim::PresetWorld(preset));
    std::ostringstream name;
    name << "sim:"
         << (preset == sim::Preset::kNone ? "" : std::string(sim::PresetName(preset)) + ":")
         << (world == sim::WorldKind::kBox ? "" : std::string(sim::WorldName(world)) + "/")
         << sim::RegimeName(given.regime.value_or(sim::PresetRegime(preset))) << "/"
         << FLAGS_sim_index;
    return std::make_unique<sim::SimulatedSource>(c, name.str());
  }
  if (FLAGS_dataset.empty()) throw std::runtime_error("--dataset is required (or --format sim)");
  if (!std::filesystem::is_directory(FLAGS_dataset)) {
    throw std::runtime_error(FLAGS_dataset + ": dataset folder does not exist");
  }
  if (FLAGS_format.empty()) return io::OpenDataset(FLAGS_dataset);
  if (FLAGS_format == "newer_college")
    return std::make_unique<io::NewerCollegeReader>(FLAGS_dataset);
  if (FLAGS_format == "ctlio") return std::make_unique<io::SimFolderReader>(FLAGS_dataset);
  if (FLAGS_format == "kitti") return std::make_unique<io::KittiReader>(FLAGS_dataset);
  throw std::runtime_error("unknown --format '" + FLAGS_format +
                           "' (newer_college, ctlio, kitti, sim)");
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage("Lidar-inertial odometry (Singer-LIO and the IMU-as-input baseline)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  try {
    const std::vector<std::string> methods = Split(FLAGS_method);
    if (methods.empty()) throw std::runtime_error("--method is empty");
    lio::OdometryConfig base;
    if (!FLAGS_config.empty()) base = lio::LoadOdometryConfig(FLAGS_config);
    if (FLAGS_out.empty()) throw std::runtime_error("--out is required");
    std::vector<lioapp::RunSummary> runs;
    for (const std::string& m : methods) {
      const lio::OdometryConfig config = base.ForMethod(lio::ParseLioMethod(m));
      auto source = OpenSource();
      const std::string out = methods.size() > 1 ? FLAGS_out + "/" + m : FLAGS_out;
      std::filesystem::create_directories(out);
      lioapp::RunOptions options;
      options.max_scans = static_cast<size_t>(std::max(0, FLAGS_max_scans));
      if (FLAGS_progress) {
        options.progress = [&m](size_t done, size_t total, const lio::ScanResult& r) {
          std::fprintf(stderr, "\r[%s] scan %zu/%zu  %-12s %5d assoc  %6.1f ms   ", m.c_str(), done,
                       total, lio::ScanStatusName(r.status), r.associations, r.milliseconds);
          if (r.status == lio::ScanStatus::kFailed || r.status == lio::ScanStatus::kDegenerate ||
              r.status == lio::ScanStatus::kImuGap) {
            std::fprintf(stderr, "\n  %s at t = %.3f s: %s\n", lio::ScanStatusName(r.status),
                         1e-9 * double(r.t_ns), r.message.c_str());
          }
        };
      }
      lioapp::RunSummary run = lioapp::RunOdometry(*source, config, options);
      if (FLAGS_progress) std::fprintf(stderr, "\n");
      io::WriteTum(out + "/trajectory.tum", run.trajectory);
      lioapp::WriteScanLog(out + "/scans.log", run);
      std::ofstream ev(out + "/evaluation.txt");
      ev << "source " << run.source << "\nmethod " << run.method << "\nscans " << run.scans.size()
         << "\nfailed_scans " << run.failed << "\ndegenerate_scans " << run.degenerate
         << "\nimu_gap_scans " << run.imu_gaps << "\nmedian_ms " << run.median_ms << "\np95_ms "
         << run.p95_ms << "\nmax_ms " << run.max_ms << "\nmedian_cpu_ms " << run.median_cpu_ms
         << "\np95_cpu_ms " << run.p95_cpu_ms << "\nmedian_preprocess_ms "
         << run.median_preprocess_ms << "\nmedian_associate_ms " << run.median_associate_ms
         << "\nmedian_solve_ms " << run.median_solve_ms << "\nmedian_map_ms " << run.median_map_ms
         << "\nmedian_marginalize_ms " << run.median_marginalize_ms << "\npeak_rss_mb "
         << run.peak_rss_kb / 1024.0 << "\n";
      if (run.ate) {
        ev << "ate_rmse_m " << run.ate->rmse << "\nate_mean_m " << run.ate->mean << "\nate_max_m "
           << run.ate->max << "\nate_pairs " << run.ate->pairs << "\n";
        io::WriteTum(out + "/ground_truth.tum", *source->GroundTruth());
        char title[160];
        std::snprintf(title, sizeof(title), "%s on %s: ATE %.4f m", run.method.c_str(),
                      run.source.c_str(), run.ate->rmse);
        lioapp::WriteTopViewSvg(out + "/trajectory_topview.svg", run.trajectory,
                                *source->GroundTruth(), run.ate->alignment, title);
      }
      if (!run.first_failure.empty()) ev << "first_failure \"" << run.first_failure << "\"\n";
      runs.push_back(std::move(run));
    }
    std::printf("\n%-12s %8s %8s %8s %6s %6s %9s %9s %9s %9s %9s\n", "method", "ATE[m]", "mean[m]",
                "max[m]", "failed", "degen", "med[ms]", "p95[ms]", "cpu_med", "cpu_p95", "peakMB");
    for (const auto& r : runs) {
      if (r.ate) {
        std::printf("%-12s %8.4f %8.4f %8.4f", r.method.c_str(), r.ate->rmse, r.ate->mean,
                    r.ate->max);
      } else {
        std::printf("%-12s %8s %8s %8s", r.method.c_str(), "-", "-", "-");
      }
      std::printf(" %6d %6d %9.1f %9.1f %9.1f %9.1f %9.1f\n", r.failed, r.degenerate, r.median_ms,
                  r.p95_ms, r.median_cpu_ms, r.p95_cpu_ms, r.peak_rss_kb / 1024.0);
      std::printf(
          "  %-10s wall-time split, median ms: preprocess %.1f  associate %.1f  solve %.1f"
          "  map %.1f  marginalise %.1f\n",
          r.method.c_str(), r.median_preprocess_ms, r.median_associate_ms, r.median_solve_ms,
          r.median_map_ms, r.median_marginalize_ms);
    }
    int bad = 0;
    for (const auto& r : runs) bad += r.failure ? 1 : 0;
    return bad ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_odometry: %s\n", e.what());
    return 2;
  }
}
