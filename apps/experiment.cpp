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
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

DEFINE_string(out, "", "Output folder (required)");
DEFINE_string(config, "",
              "YAML config (default: data/sim_lio.yaml of the source tree, "
              "data/newer_college_lio.yaml with --sim_preset newer_college)");
DEFINE_string(regimes, "slow,medium,fast", "Comma-separated regimes (also walking, vehicle)");
DEFINE_string(sim_preset, "",
              "Recording preset: none | newer_college (sets world, regime, sensors, IMU, duration; "
              "explicit --world/--regimes/--duration/--beams/--firing_decimation/--body_centric "
              "win)");
DEFINE_string(world, "box", "Simulated world: box | street | corridor | park | indoor");
DEFINE_string(methods, "singer_lio,imu_input,lidar_gyro,lidar_only", "Comma-separated methods");
DEFINE_int32(sequences, 20, "Sequences per regime (the paper: 20)");
DEFINE_int32(first_sequence, 0, "Index of the first sequence");
DEFINE_double(duration, 20.0, "Sequence length [s] (the paper: 20)");
DEFINE_int32(beams, 128, "Lidar beams (the paper: 128)");
DEFINE_int32(firing_decimation, 1, "Keep every n-th lidar firing (1 = full resolution)");
DEFINE_int32(threads, 0, "Parallel runs (0 = number of cores)");
DEFINE_bool(body_centric, false, "Simulate the paper's body-centric accelerometer model");
DEFINE_double(failure_ate, 1.0, "A run whose ATE exceeds this [m] counts as a failure");

namespace {

using namespace ctlio;

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

struct Job {
  std::string regime;
  int index = 0;
  std::string method;
  lioapp::RunSummary run;
  bool done = false;
  std::string error;
};

// Grouped bar chart (one group per regime, one bar per method) of the overall RMSE ATE, log
// scale in centimetres, as a self-contained SVG.
void WriteBarSvg(const std::string& path,
                 const std::vector<std::tuple<std::string, std::string, double>>& bars,
                 const std::vector<std::string>& regimes, const std::vector<std::string>& methods) {
  const char* colours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#ff7f0e"};
  const double width = 720, height = 400, left = 70, bottom = 330, top = 40;
  double lo = 1e9, hi = -1e9;
  for (const auto& b : bars) {
    const double v = std::get<2>(b);
    if (std::isfinite(v) && v > 0) {
      lo = std::min(lo, std::log10(100 * v));
      hi = std::max(hi, std::log10(100 * v));
    }
  }
  if (lo > hi) lo = -1, hi = 1;
  lo = std::floor(lo) - 0.0;
  hi = std::ceil(hi + 1e-9);
  const auto y_of = [&](double cm) {
    return bottom - (std::log10(cm) - lo) / (hi - lo) * (bottom - top);
  };
  std::ofstream f(path);
  f << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
    << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
       "fill='white'/>\n<text x='"
    << left << "' y='20' font-size='14'>Table II: overall RMSE ATE per regime [cm, log scale]"
    << "</text>\n";
  for (int e = static_cast<int>(lo); e <= static_cast<int>(hi); ++e) {
    const double y = y_of(std::pow(10.0, e));
    f << "<line x1='" << left << "' x2='" << width - 10 << "' y1='" << y << "' y2='" << y
      << "' stroke='#ddd'/><text x='" << left - 8 << "' y='" << y + 4 << "' text-anchor='end'>"
      << std::pow(10.0, e) << "</text>\n";
  }
  const double group = (width - left - 20) / std::max<size_t>(1, regimes.size());
  const double bar = group * 0.8 / std::max<size_t>(1, methods.size());
  for (size_t r = 0; r < regimes.size(); ++r) {
    const double x0 = left + r * group + group * 0.1;
    f << "<text x='" << x0 + group * 0.4 << "' y='" << bottom + 18 << "' text-anchor='middle'>"
      << regimes[r] << "</text>\n";
    for (size_t m = 0; m < methods.size(); ++m) {
      for (const auto& b : bars) {
        if (std::get<0>(b) != regimes[r] || std::get<1>(b) != methods[m]) continue;
        const double v = std::get<2>(b);
        if (!std::isfinite(v) || v <= 0) continue;
        const double y = y_of(100 * v);
        f << "<rect x='" << x0 + m * bar << "' y='" << y << "' width='" << bar * 0.9 << "' height='"
          << bottom - y << "' fill='" << colours[m % 6] << "'/><text x='"
          << x0 + m * bar + bar * 0.45 << "' y='" << y - 3 << "' text-anchor='middle' "
          << "font-size='10'>" << std::round(1000 * v) / 10 << "</text>\n";
      }
    }
  }
  for (size_t m = 0; m < methods.size(); ++m) {
    f << "<rect x='" << left + 10 + 150 * m << "' y='" << height - 30
      << "' width='12' height='12' fill='" << colours[m % 6] << "'/><text x='"
      << left + 26 + 150 * m << "' y='" << height - 20 << "'>" << methods[m] << "</text>\n";
  }
  f << "</svg>\n";
}

}  // namespace

// A flag's value when it should apply: always without a preset, only if given explicitly with
// one (the preset's value stands otherwise).
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  if (FLAGS_sim_preset.empty() || !gflags::GetCommandLineFlagInfoOrDie(flag).is_default) {
    return value;
  }
  return std::nullopt;
}

int main(int argc, char** argv) {
  gflags::SetUsageMessage("Table II: Singer-LIO vs the IMU-as-input baseline in simulation");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  try {
    if (FLAGS_out.empty()) throw std::runtime_error("--out is required");
    std::filesystem::create_directories(FLAGS_out);
    // Default configuration: the one written for the simulated sensors.
    const std::string config_path =
        !FLAGS_config.empty() ? FLAGS_config
        : FLAGS_sim_preset == "newer_college"
            ? std::string(CTLIO_SOURCE_DIR) + "/data/newer_college_lio.yaml"
            : std::string(CTLIO_SOURCE_DIR) + "/data/sim_lio.yaml";
    const lio::OdometryConfig base = lio::LoadOdometryConfig(config_path);
    const sim::Preset preset = sim::ParsePreset(FLAGS_sim_preset);
    sim::SimOverrides given;  // the settings every sequence shares (regime: per job)
    if (auto w = Given("world", FLAGS_world)) given.world = sim::ParseWorld(*w);
    given.duration_s = Given("duration", FLAGS_duration);
    given.beams = Given("beams", FLAGS_beams);
    given.firing_decimation = Given("firing_decimation", FLAGS_firing_decimation);
    given.body_centric = Given("body_centric", FLAGS_body_centric);
    const std::string world_name = sim::WorldName(given.world.value_or(sim::PresetWorld(preset)));
    const auto regimes =
        Split(Given("regimes", FLAGS_regimes).value_or(sim::RegimeName(sim::PresetRegime(preset))));
    const auto methods = Split(FLAGS_methods);
    for (const auto& r : regimes) sim::ParseRegime(r);
    const sim::SimConfig shared = sim::PresetConfig(preset, 0, sim::kExperimentSeed, given);
    for (const auto& m : methods) lio::ParseLioMethod(m);

    std::vector<Job> jobs;
    // Slow jobs first (fast regime, all methods) so that the tail of the schedule is short.
    for (auto r = regimes.rbegin(); r != regimes.rend(); ++r) {
      for (int i = FLAGS_first_sequence; i < FLAGS_first_sequence + FLAGS_sequences; ++i) {
        for (const auto& m : methods) jobs.push_back({*r, i, m});
      }
    }
    const int threads =
        FLAGS_threads > 0 ? FLAGS_threads : std::max(1u, std::thread::hardware_concurrency());
    std::atomic<size_t> next{0};
    std::atomic<size_t> finished{0};
    std::mutex print;
    const auto start = std::chrono::steady_clock::now();
    auto worker = [&]() {
      for (size_t j = next++; j < jobs.size(); j = next++) {
        Job& job = jobs[j];
        try {
          sim::SimOverrides job_given = given;
          job_given.regime = sim::ParseRegime(job.regime);
          const sim::SimConfig c =
              sim::PresetConfig(preset, job.index, sim::kExperimentSeed, job_given);
          sim::SimulatedSource source(c, "sim:" + job.regime + "/" + std::to_string(job.index));
          const lio::OdometryConfig config = base.ForMethod(lio::ParseLioMethod(job.method));
          job.run = lioapp::RunOdometry(source, config, {}, FLAGS_failure_ate);
          job.done = true;
        } catch (const std::exception& e) {
          job.error = e.what();
        }
        const size_t n = ++finished;
        std::lock_guard<std::mutex> lock(print);
        const double el =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "[%zu/%zu %6.0f s] %-6s %2d %-10s ", n, jobs.size(), el,
                     job.regime.c_str(), job.index, job.method.c_str());
        if (!job.done) {
          std::fprintf(stderr, "ERROR %s\n", job.error.c_str());
        } else {
          std::fprintf(stderr, "ATE %.4f m  failed scans %d  median %.1f ms%s\n",
                       job.run.ate ? job.run.ate->rmse : NAN, job.run.failed, job.run.median_ms,
                       job.run.failure ? "  FAILURE" : "");
        }
      }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();

    // Per run.
    std::ofstream csv(FLAGS_out + "/results.csv");
    csv << "regime,sequence,method,ate_rmse_m,ate_pairs,failed_scans,degenerate_scans,failure,"
           "median_ms,p95_ms,max_ms,median_cpu_ms,p95_cpu_ms,error\n";
    for (const Job& j : jobs) {
      csv << j.regime << ',' << j.index << ',' << j.method << ','
          << (j.done && j.run.ate ? j.run.ate->rmse : NAN) << ','
          << (j.done && j.run.ate ? j.run.ate->pairs : 0) << ',' << j.run.failed << ','
          << j.run.degenerate << ',' << (!j.done || j.run.failure ? 1 : 0) << ',' << j.run.median_ms
          << ',' << j.run.p95_ms << ',' << j.run.max_ms << ',' << j.run.median_cpu_ms << ','
          << j.run.p95_cpu_ms << ",\"" << j.error << "\"\n";
    }
    // Table: overall RMSE = sqrt(Σ n_i·rmse_i² / Σ n_i) over the runs of a regime that did not
    // fail (so one diverged run is counted as a failure and does not swamp the mean), and the
    // same over all runs for completeness.
    std::ostringstream md;
    md << "# Table II (ctlio): RMSE ATE [m] per regime and method, world " << world_name
       << (preset == sim::Preset::kNone ? "" : std::string(", preset ") + sim::PresetName(preset))
       << "\n\n";
    md << "Settings: " << FLAGS_sequences << " sequences per regime (from index "
       << FLAGS_first_sequence << "), " << shared.duration_s << " s each, " << shared.lidar.beams
       << " beams × " << shared.lidar.firings_per_revolution << " firings at "
       << shared.lidar.rate_hz << " Hz, firing decimation " << shared.lidar.firing_decimation
       << ", IMU " << shared.imu.rate_hz << " Hz, "
       << (shared.imu.body_centric ? "body-centric" : "exact specific-force") << " IMU, config "
       << std::filesystem::path(config_path).filename().string() << ". ";
    const bool full = preset == sim::Preset::kNone && FLAGS_sequences >= 20 &&
                      shared.duration_s >= 20 && shared.lidar.beams >= 128 &&
                      shared.lidar.firing_decimation == 1;
    md << (preset != sim::Preset::kNone ? "Preset settings.\n\n"
           : full                       ? "Full paper settings.\n\n"
                  : "**REDUCED settings** (not the paper's 20 × 20 s × 128 beams).\n\n");
    md << "| regime | method | RMSE ATE (non-failed) [m] | RMSE ATE (all) [m] | failures | median "
          "ms/scan (wall) | p95 ms/scan (wall) | median CPU ms/scan |\n"
          "|---|---|---|---|---|---|---|---|\n";
    std::vector<std::tuple<std::string, std::string, double>> bars;
    for (const auto& r : regimes) {
      for (const auto& m : methods) {
        double s_ok = 0, n_ok = 0, s_all = 0, n_all = 0;
        int failures = 0;
        std::vector<double> med, p95, cpu;
        for (const Job& j : jobs) {
          if (j.regime != r || j.method != m) continue;
          if (!j.done || j.run.failure) ++failures;
          if (!j.done || !j.run.ate) continue;
          const double n = double(j.run.ate->pairs);
          const double e2 = j.run.ate->rmse * j.run.ate->rmse;
          if (std::isfinite(e2)) {
            s_all += n * e2;
            n_all += n;
            if (!j.run.failure) {
              s_ok += n * e2;
              n_ok += n;
            }
          }
          med.push_back(j.run.median_ms);
          p95.push_back(j.run.p95_ms);
          cpu.push_back(j.run.median_cpu_ms);
        }
        char line[256];
        std::snprintf(line, sizeof(line), "| %s | %s | %.4f | %.4f | %d | %.1f | %.1f | %.1f |\n",
                      r.c_str(), m.c_str(), n_ok > 0 ? std::sqrt(s_ok / n_ok) : NAN,
                      n_all > 0 ? std::sqrt(s_all / n_all) : NAN, failures,
                      lioapp::Percentile(med, 0.5), lioapp::Percentile(p95, 0.5),
                      lioapp::Percentile(cpu, 0.5));
        md << line;
        bars.emplace_back(r, m, n_all > 0 ? std::sqrt(s_all / n_all) : NAN);
      }
    }
    const double el =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    md << "\nWall time " << el << " s on " << threads << " threads. A failure is a run with a "
       << "failed scan or an ATE above " << FLAGS_failure_ate << " m.\n";
    std::ofstream(FLAGS_out + "/table.md") << md.str();
    std::printf("%s", md.str().c_str());
    WriteBarSvg(FLAGS_out + "/table2.svg", bars, regimes, methods);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_experiment: %s\n", e.what());
    return 2;
  }
}
