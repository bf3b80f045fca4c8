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
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/calibration_output.h"
#include "lio/config_origin.h"
#include "lio/experiment_results.h"
#include "lio/output_files.h"
#include "lio/run_odometry.h"

DEFINE_string(out, "", "Output folder (required)");
DEFINE_string(config, "",
              "YAML config, or a comma-separated list whose later files win key by key "
              "(default: data/sim_lio.yaml of the source tree, data/newer_college_lio.yaml with "
              "--sim_preset newer_college)");
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

using namespace ctlio;

lioapp::OutputFiles written;  // every file the run writes, listed at its end

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
  std::string scenario;
  double outage_s = 0.0;  // 0 = none
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
  std::ofstream f = io::OpenForWriting(path);
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
          << "font-size='10'>" << lioapp::CentimetreLabel(v) << "</text>\n";
      }
    }
  }
  for (size_t m = 0; m < methods.size(); ++m) {
    f << "<rect x='" << left + 10 + 150 * m << "' y='" << height - 30
      << "' width='12' height='12' fill='" << colours[m % 6] << "'/><text x='"
      << left + 26 + 150 * m << "' y='" << height - 20 << "'>" << methods[m] << "</text>\n";
  }
  f << "</svg>\n";
  io::CloseChecked(f, path);
}

// OUT/extrinsic.csv: per run with a perturbed nominal or an estimated extrinsic, the starting
// and final extrinsic errors against the truth (rotation [deg], translation [cm]), the final
// marginal σ per axis ([ρ] cm, [φ] deg) and whether the error lies within 3σ on every axis, the
// ATE (sim/extrinsic_error.h), and with a calibration warm-up replay the scans it revised and the
// ATE of the trajectory as returned live (RunSummary::live_ate; = ate_m without a replay).
void WriteExtrinsicErrors(const std::string& out, const std::vector<Job>& jobs) {
  std::ostringstream csv;
  csv << "regime,sequence,method,ate_m,initial_error_deg,initial_error_cm,error_deg,error_cm,"
         "sigma_x_cm,sigma_y_cm,sigma_z_cm,sigma_rx_deg,sigma_ry_deg,sigma_rz_deg,"
         "rotation_within_3sigma,translation_within_3sigma,warmup_replayed_scans,live_ate_m\n";
  bool any = false;
  for (const Job& j : jobs) {
    if (!j.done || !j.run.true_extrinsic) continue;
    const lioapp::RunSummary& run = j.run;
    const bool perturbed =
        (run.true_extrinsic->Matrix() - run.initial_extrinsic.Matrix()).norm() > 0.0;
    if (!perturbed && !run.extrinsic_estimated) continue;
    any = true;
    const sim::ExtrinsicErrorSize e0 =
        sim::MeasureExtrinsicError(run.initial_extrinsic, *run.true_extrinsic);
    const sim::ExtrinsicErrorSize e1 =
        sim::MeasureExtrinsicError(run.final_extrinsic, *run.true_extrinsic);
    const Vec6& s = run.final_extrinsic_sigma;
    csv << j.regime << ',' << j.index << ',' << j.method << ',' << (run.ate ? run.ate->rmse : NAN)
        << ',' << e0.rotation_deg << ',' << 100 * e0.translation_m << ',' << e1.rotation_deg << ','
        << 100 * e1.translation_m;
    if (run.extrinsic_estimated) {
      const sim::SigmaCoverage c = sim::CoveredBySigma(run.final_extrinsic, *run.true_extrinsic, s);
      for (int i = 0; i < 6; ++i) csv << ',' << s[i] * (i < 3 ? 100.0 : 180.0 / M_PI);
      csv << ',' << c.rotation << ',' << c.translation;
    } else {
      csv << ",,,,,,,,";
    }
    csv << ',' << run.warmup_replayed_scans << ',' << (run.live_ate ? run.live_ate->rmse : NAN)
        << "\n";
  }
  if (!any) return;
  io::WriteTextFile(out + "/extrinsic.csv", csv.str());
  written.Add(out + "/extrinsic.csv", "extrinsic error [deg, cm] and sigmas per run");
}

// The settings that must be equal for runs to be pooled, one "key value" per line.
std::string SettingsText(const std::string& config_path, const std::string& preset,
                         const std::string& world, const ctlio::sim::SimConfig& shared) {
  std::ostringstream s;
  s << "preset " << preset << "\nworld " << world << "\nduration_s " << shared.duration_s
    << "\nbeams " << shared.lidar.beams << "\nfiring_decimation " << shared.lidar.firing_decimation
    << "\nimu_model " << (shared.imu.body_centric ? "body-centric" : "exact-specific-force")
    << "\nconfig " << std::filesystem::path(config_path).filename().string() << "\nfailure_ate_m "
    << FLAGS_failure_ate << "\n";
  // Only when set, so that single-IMU settings (and merges with earlier jobs) stay as they were.
  if (!FLAGS_imus.empty()) s << "imus " << FLAGS_imus << "\n";
  if (!FLAGS_extrinsic_error.empty()) s << "extrinsic_error " << FLAGS_extrinsic_error << "\n";
  if (shared.lidar.rate_hz != 10.0) s << "lidar_rate_hz " << shared.lidar.rate_hz << "\n";
  return s.str();
}

std::string ReadText(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open (not an experiment output folder?)");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::map<std::string, std::string> ParseSettings(const std::string& text) {
  std::map<std::string, std::string> kv;
  std::istringstream in(text);
  std::string key, value;
  while (in >> key >> value) kv[key] = value;
  return kv;
}

// OUT/table.md, OUT/pooled.csv and OUT/table2.svg from the per-run rows.
void WriteTable(const std::string& out, const std::string& settings,
                const std::vector<lioapp::RunRow>& rows, const std::string& provenance) {
  const auto kv = ParseSettings(settings);
  std::map<std::string, std::set<int>> sequences;
  for (const auto& r : rows) sequences[r.regime].insert(r.sequence);
  size_t per_regime = 0;
  int lo = 1 << 30, hi = -1;
  for (const auto& [regime, set] : sequences) {
    per_regime = per_regime == 0 ? set.size() : std::min(per_regime, set.size());
    lo = std::min(lo, *set.begin());
    hi = std::max(hi, *set.rbegin());
  }
  std::ostringstream md;
  const std::string preset = kv.count("preset") ? kv.at("preset") : "none";
  md << "# Table II (ctlio): RMSE ATE [m] per regime, method and scenario, world " << kv.at("world")
     << (preset == "none" ? "" : ", preset " + preset) << "\n\nSettings: " << per_regime
     << " sequences per regime (indices " << lo << "–" << hi << "), " << kv.at("duration_s")
     << " s each, " << kv.at("beams") << " beams, firing decimation " << kv.at("firing_decimation")
     << ", " << kv.at("imu_model") << " IMU, config " << kv.at("config") << ". ";
  const bool full = preset == "none" && per_regime >= 20 && std::stod(kv.at("duration_s")) >= 20 &&
                    std::stoi(kv.at("beams")) >= 128 && kv.at("firing_decimation") == "1";
  md << (preset != "none" ? "Preset settings.\n\n"
         : full           ? "Full paper settings.\n\n"
                          : "**REDUCED settings** (not the paper's 20 × 20 s × 128 beams).\n\n");
  const auto cells = lioapp::PoolRows(rows);
  md << lioapp::PooledTableMarkdown(cells);
  md << "\n"
     << provenance << " A failure is a run with a failed scan or an ATE above "
     << kv.at("failure_ate_m") << " m. Scenario outage_Ls: no IMU samples for L s centred on the "
     << "sequence midpoint. Scans degenerate: status `degenerate`, the lidar did not fix the pose "
     << "(results.csv degenerate_scans); degen_dir: the lidar term had a degenerate direction, "
     << "whatever the status (with an IMU the scan stays `ok`; degenerate_direction_scans).\n";
  io::WriteTextFile(out + "/table.md", md.str());
  written.Add(out + "/table.md", "the table above (Markdown)");
  std::printf("%s", md.str().c_str());
  lioapp::WritePooledCsv(out + "/pooled.csv", cells);
  written.Add(out + "/pooled.csv", "the table's numbers, one line per cell (CSV)");
  std::vector<std::tuple<std::string, std::string, double>> bars;
  std::vector<std::string> regimes, methods;
  for (const auto& c : cells) {
    if (c.scenario != cells.front().scenario) continue;
    bars.emplace_back(c.regime, c.method, c.rmse_all);
    if (std::find(regimes.begin(), regimes.end(), c.regime) == regimes.end())
      regimes.push_back(c.regime);
    if (std::find(methods.begin(), methods.end(), c.method) == methods.end())
      methods.push_back(c.method);
  }
  WriteBarSvg(out + "/table2.svg", bars, regimes, methods);
  written.Add(out + "/table2.svg", "bar plot of the RMSE ATE per regime and method [cm]");
}

// OUT/nees.csv (one line per run: mean NEES of the pose, its translation and rotation, the
// scans, and the error of every IMU's final bias estimate against the true initial bias) and
// OUT/nees.md (means per regime, method and scenario over the runs' scans; 6 resp. 3 if
// consistent).
void WriteNees(const std::string& out, const std::vector<Job>& jobs) {
  std::ofstream f = io::OpenForWriting(out + "/nees.csv");
  f << "regime,sequence,method,scenario,scans,nees_pose,nees_translation,nees_rotation,"
       "bias_error_accel,bias_error_gyro\n"
    << std::setprecision(10);
  struct Sum {
    double pose = 0, translation = 0, rotation = 0;
    size_t scans = 0;
    int runs = 0;
  };
  std::vector<std::pair<std::string, Sum>> cells;
  for (const Job& j : jobs) {
    if (!j.done) continue;
    // Bias error: RMS over the IMUs of |b̂ − b| (accelerometer, gyro) at the last scan.
    double ea = NAN, eg = NAN;
    if (!j.run.final_biases.empty()) {
      ea = eg = 0.0;
      size_t n = 0;
      for (size_t k = 0; k < j.run.final_biases.size() && k < j.run.true_biases.size(); ++k) {
        if (!j.run.true_biases[k]) continue;
        const Vec6 d = j.run.final_biases[k] - *j.run.true_biases[k];
        ea += d.head<3>().squaredNorm();
        eg += d.tail<3>().squaredNorm();
        ++n;
      }
      ea = n ? std::sqrt(ea / double(n)) : NAN;
      eg = n ? std::sqrt(eg / double(n)) : NAN;
    }
    f << j.regime << ',' << j.index << ',' << j.method << ',' << j.scenario << ','
      << j.run.nees.size() << ',' << lioapp::Mean(j.run.nees) << ','
      << lioapp::Mean(j.run.nees_translation) << ',' << lioapp::Mean(j.run.nees_rotation) << ','
      << ea << ',' << eg << '\n';
    const std::string key = j.regime + " | " + j.method + " | " + j.scenario;
    auto it =
        std::find_if(cells.begin(), cells.end(), [&](const auto& c) { return c.first == key; });
    if (it == cells.end()) it = cells.insert(cells.end(), {key, Sum{}});
    for (size_t k = 0; k < j.run.nees.size(); ++k) {
      it->second.pose += j.run.nees[k];
      it->second.translation += j.run.nees_translation[k];
      it->second.rotation += j.run.nees_rotation[k];
    }
    it->second.scans += j.run.nees.size();
    ++it->second.runs;
  }
  io::CloseChecked(f, out + "/nees.csv");
  written.Add(out + "/nees.csv", "mean NEES and bias errors per run");
  std::ostringstream md;
  md << "| regime | method | scenario | runs | scans | NEES pose (6) | translation (3) | rotation "
        "(3) |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& [key, c] : cells) {
    const double n = std::max<double>(1.0, double(c.scans));
    md << "| " << key << " | " << c.runs << " | " << c.scans << " | " << c.pose / n << " | "
       << c.translation / n << " | " << c.rotation / n << " |\n";
  }
  io::WriteTextFile(out + "/nees.md", md.str());
  written.Add(out + "/nees.md", "the consistency table (Markdown)");
  std::printf("\nConsistency (mean NEES over all scans of the runs):\n%s", md.str().c_str());
}

// --merge: pool the results of earlier jobs with equal settings.
void Merge() {
  std::string settings;
  std::vector<lioapp::RunRow> rows;
  std::set<std::tuple<std::string, int, std::string, std::string>> seen;
  const auto dirs = Split(FLAGS_merge);
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
  WriteTable(FLAGS_out, settings, rows,
             "Merged from " + std::to_string(dirs.size()) + " jobs (" + FLAGS_merge + ").");
}

}  // namespace

// A flag applies unless a preset is chosen and the flag was not given explicitly.
template <class T>
std::optional<T> Given(const char* flag, const T& value) {
  return ctlio::apps::Given(!FLAGS_sim_preset.empty(), flag, value);
}

// OUT/calibration.csv (one line per run and IMU): the online calibration's final clock offset,
// its marginal σ, the simulated truth, the error and |error| ≤ 3σ, and the run's ATE; and the
// first and last σ (whether it shrinks: observability).
void WriteCalibration(const std::string& out, const std::vector<Job>& jobs) {
  std::ofstream f = io::OpenForWriting(out + "/calibration.csv");
  f << "regime,sequence,method,imu,time_offset_s,sigma_s,first_sigma_s,true_s,error_s,"
       "within_3sigma,ate_rmse_m\n"
    << std::setprecision(9);
  for (const Job& j : jobs) {
    if (!j.done) continue;
    const lio::ScanResult* last = lioapp::LastCalibration(j.run);
    if (last == nullptr) continue;
    const lio::ScanResult* first = nullptr;
    for (const auto& r : j.run.scans) {
      if (!r.calibration.time_offset_sigma_s.empty()) {
        first = &r;
        break;
      }
    }
    const auto& c = last->calibration;
    for (size_t i = 0; i < c.time_offset_s.size(); ++i) {
      const double sigma = i < c.time_offset_sigma_s.size() ? c.time_offset_sigma_s[i] : NAN;
      const double first_sigma =
          first != nullptr && i < first->calibration.time_offset_sigma_s.size()
              ? first->calibration.time_offset_sigma_s[i]
              : NAN;
      const bool known = i < j.run.true_time_offsets.size() && j.run.true_time_offsets[i];
      const double truth = known ? *j.run.true_time_offsets[i] : 0.0;
      const double error = c.time_offset_s[i] - truth;
      f << j.regime << ',' << j.index << ',' << j.method << ',' << i << ',' << c.time_offset_s[i]
        << ',' << sigma << ',' << first_sigma << ',' << truth << ',' << error << ','
        << (std::abs(error) <= 3 * sigma ? 1 : 0) << ',' << (j.run.ate ? j.run.ate->rmse : NAN)
        << "\n";
    }
  }
  io::CloseChecked(f, out + "/calibration.csv");
  written.Add(out + "/calibration.csv",
              "clock offset estimate, sigma and error [s] per run and IMU");
}

// OUT/observability.csv (one line per run and calibration coordinate, with the observability
// check of the online calibration, calibration_observability.h): ν after the last scan, whether
// the coordinate was unobservable then, and the fraction of the scans after which it was.
void WriteObservability(const std::string& out, const std::vector<Job>& jobs) {
  std::ostringstream csv;
  csv << "regime,sequence,method,coordinate,final_information,final_status,"
         "unobservable_fraction\n"
      << std::setprecision(6);
  bool any = false;
  for (const Job& j : jobs) {
    if (!j.done || !lioapp::HasObservability(j.run)) continue;
    const lio::ScanResult* last = lioapp::LastCalibration(j.run);
    if (last == nullptr) continue;
    any = true;
    const std::vector<std::string> names = lioapp::CalibrationCoordinates(last->calibration);
    const std::vector<double> fraction = lioapp::UnobservableFraction(j.run);
    const auto& c = last->calibration;
    for (size_t i = 0; i < names.size(); ++i) {
      csv << j.regime << ',' << j.index << ',' << j.method << ',' << names[i] << ',';
      lioapp::WriteCoordinateObservability(c, i, csv);
      csv << ',' << (i < fraction.size() ? fraction[i] : NAN) << "\n";
    }
  }
  if (!any) return;
  io::WriteTextFile(out + "/observability.csv", csv.str());
  written.Add(out + "/observability.csv", "observability of every calibration coordinate per run");
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
    // Default configuration: the one written for the simulated sensors.
    const std::string config_path =
        !FLAGS_config.empty() ? FLAGS_config
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
    const std::string world_name = sim::WorldName(given.world.value_or(sim::PresetWorld(preset)));
    const auto regimes =
        Split(Given("regimes", FLAGS_regimes).value_or(sim::RegimeName(sim::PresetRegime(preset))));
    const auto methods = Split(FLAGS_methods);
    for (const auto& r : regimes) sim::ParseRegime(r);
    const sim::SimConfig shared = sim::PresetConfig(preset, 0, sim::kExperimentSeed, given);
    for (const auto& m : methods) lio::ParseLioMethod(m);
    const sim::ExtrinsicError extrinsic_error = sim::ParseExtrinsicError(FLAGS_extrinsic_error);
    // Scenarios: (name, outage length); the nominal one first.
    std::vector<std::pair<std::string, double>> scenarios;
    if (FLAGS_imu_outage.empty() || FLAGS_nominal) scenarios.push_back({"none", 0.0});
    for (const auto& text : Split(FLAGS_imu_outage)) {
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
    const std::string settings =
        SettingsText(config_path, sim::PresetName(preset), world_name, shared);
    io::WriteTextFile(FLAGS_out + "/settings.txt", settings);
    written.Add(FLAGS_out + "/settings.txt", "the settings runs must share to be merged");
    lioapp::WriteResultsCsv(FLAGS_out + "/results.csv", rows);
    written.Add(FLAGS_out + "/results.csv", "one line per run: ATE [m], scan counts, ms (CSV)");
    if (FLAGS_pose_covariance) WriteNees(FLAGS_out, jobs);
    if (FLAGS_estimate_time_offset || base.calibration.estimate_time_offset) {
      WriteCalibration(FLAGS_out, jobs);
    }
    WriteExtrinsicErrors(FLAGS_out, jobs);
    WriteObservability(FLAGS_out, jobs);
    const double el =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ostringstream provenance;
    provenance << "Wall time " << el << " s on " << threads << " threads.";
    WriteTable(FLAGS_out, settings, rows, provenance.str());
    std::printf("\n");
    std::fflush(stdout);
    written.Print(std::cout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_experiment: %s\n", e.what());
    return 2;
  }
}
