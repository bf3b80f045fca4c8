#include "experiment_outputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "calibration_output.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/sim/extrinsic_error.h"

namespace ctlio::lioapp {

namespace {

std::map<std::string, std::string> ParseSettings(const std::string& text) {
  std::map<std::string, std::string> kv;
  std::istringstream in(text);
  std::string key, value;
  while (in >> key >> value) kv[key] = value;
  return kv;
}

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
          << "font-size='10'>" << CentimetreLabel(v) << "</text>\n";
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

}  // namespace

// OUT/extrinsic.csv: per run with a perturbed nominal or an estimated extrinsic, the starting
// and final extrinsic errors against the truth (rotation [deg], translation [cm]), the final
// marginal σ per axis ([ρ] cm, [φ] deg) and whether the error lies within 3σ on every axis, the
// ATE (sim/extrinsic_error.h), and with a calibration warm-up replay the scans it revised and the
// ATE of the trajectory as returned live (RunSummary::live_ate; = ate_m without a replay).
void WriteExtrinsicErrors(const std::string& out, const std::vector<ExperimentJob>& jobs,
                          OutputFiles* written) {
  std::ostringstream csv;
  csv << "regime,sequence,method,ate_m,initial_error_deg,initial_error_cm,error_deg,error_cm,"
         "sigma_x_cm,sigma_y_cm,sigma_z_cm,sigma_rx_deg,sigma_ry_deg,sigma_rz_deg,"
         "rotation_within_3sigma,translation_within_3sigma,warmup_replayed_scans,live_ate_m\n";
  bool any = false;
  for (const ExperimentJob& j : jobs) {
    if (!j.done || !j.run.true_extrinsic) continue;
    const RunSummary& run = j.run;
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
  written->Add(out + "/extrinsic.csv", "extrinsic error [deg, cm] and sigmas per run");
}

// OUT/table.md, OUT/pooled.csv and OUT/table2.svg from the per-run rows.
void WriteTable(const std::string& out, const std::string& settings,
                const std::vector<RunRow>& rows, const std::string& provenance,
                OutputFiles* written) {
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
  const auto cells = PoolRows(rows);
  md << PooledTableMarkdown(cells);
  md << "\n"
     << provenance << " A failure is a run with a failed scan or an ATE above "
     << kv.at("failure_ate_m") << " m. Scenario outage_Ls: no IMU samples for L s centred on the "
     << "sequence midpoint. Scans degenerate: status `degenerate`, the lidar did not fix the pose "
     << "(results.csv degenerate_scans); degen_dir: the lidar term had a degenerate direction, "
     << "whatever the status (with an IMU the scan stays `ok`; degenerate_direction_scans).\n";
  io::WriteTextFile(out + "/table.md", md.str());
  written->Add(out + "/table.md", "the table above (Markdown)");
  std::printf("%s", md.str().c_str());
  WritePooledCsv(out + "/pooled.csv", cells);
  written->Add(out + "/pooled.csv", "the table's numbers, one line per cell (CSV)");
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
  written->Add(out + "/table2.svg", "bar plot of the RMSE ATE per regime and method [cm]");
}

// OUT/nees.csv (one line per run: mean NEES of the pose, its translation and rotation, the
// scans, and the error of every IMU's final bias estimate against the true initial bias) and
// OUT/nees.md (means per regime, method and scenario over the runs' scans; 6 resp. 3 if
// consistent).
void WriteNees(const std::string& out, const std::vector<ExperimentJob>& jobs,
               OutputFiles* written) {
  std::ofstream f = io::OpenForWriting(out + "/nees.csv");
  f << "regime,sequence,method,scenario,scans,nees_pose,nees_translation,nees_rotation,"
       "bias_error_accel,bias_error_gyro,coverage_x,coverage_y,coverage_z,coverage_rx,"
       "coverage_ry,coverage_rz\n"
    << std::setprecision(10);
  struct Sum {
    double pose = 0, translation = 0, rotation = 0;
    size_t scans = 0;
    std::array<size_t, 6> inside{};  // per axis, the scans inside ±3σ
    int runs = 0;
  };
  std::vector<std::pair<std::string, Sum>> cells;
  for (const ExperimentJob& j : jobs) {
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
      << j.run.nees.size() << ',' << Mean(j.run.nees) << ',' << Mean(j.run.nees_translation) << ','
      << Mean(j.run.nees_rotation) << ',' << ea << ',' << eg;
    for (const size_t inside : j.run.nees_inside_3sigma) {
      f << ',' << (j.run.nees.empty() ? NAN : double(inside) / double(j.run.nees.size()));
    }
    f << '\n';
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
    for (size_t a = 0; a < 6; ++a) it->second.inside[a] += j.run.nees_inside_3sigma[a];
    ++it->second.runs;
  }
  io::CloseChecked(f, out + "/nees.csv");
  written->Add(out + "/nees.csv", "mean NEES and bias errors per run");
  std::ostringstream md;
  md << "| regime | method | scenario | runs | scans | NEES pose (6) | translation (3) | rotation "
        "(3) | 3σ coverage x y z rx ry rz (%) |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [key, c] : cells) {
    const double n = std::max<double>(1.0, double(c.scans));
    md << "| " << key << " | " << c.runs << " | " << c.scans << " | " << c.pose / n << " | "
       << c.translation / n << " | " << c.rotation / n << " |";
    for (const size_t inside : c.inside) {
      char pct[16];
      std::snprintf(pct, sizeof(pct), " %.1f", 100.0 * double(inside) / n);
      md << pct;
    }
    md << " |\n";
  }
  io::WriteTextFile(out + "/nees.md", md.str());
  written->Add(out + "/nees.md", "the consistency table (Markdown)");
  std::printf("\nConsistency (mean NEES over all scans of the runs):\n%s", md.str().c_str());
}

// OUT/calibration.csv (one line per run and IMU): the online calibration's final clock offset,
// its marginal σ, the simulated truth, the error and |error| ≤ 3σ, and the run's ATE; and the
// first and last σ (whether it shrinks: observability).
void WriteCalibration(const std::string& out, const std::vector<ExperimentJob>& jobs,
                      OutputFiles* written) {
  std::ofstream f = io::OpenForWriting(out + "/calibration.csv");
  f << "regime,sequence,method,imu,time_offset_s,sigma_s,first_sigma_s,true_s,error_s,"
       "within_3sigma,ate_rmse_m\n"
    << std::setprecision(9);
  for (const ExperimentJob& j : jobs) {
    if (!j.done) continue;
    const lio::ScanResult* last = LastCalibration(j.run);
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
  written->Add(out + "/calibration.csv",
               "clock offset estimate, sigma and error [s] per run and IMU");
}

// OUT/observability.csv (one line per run and calibration coordinate, with the observability
// check of the online calibration, calibration_observability.h): ν after the last scan, whether
// the coordinate was unobservable then, and the fraction of the scans after which it was.
void WriteObservability(const std::string& out, const std::vector<ExperimentJob>& jobs,
                        OutputFiles* written) {
  std::ostringstream csv;
  csv << "regime,sequence,method,coordinate,final_information,final_status,"
         "unobservable_fraction\n"
      << std::setprecision(6);
  bool any = false;
  for (const ExperimentJob& j : jobs) {
    if (!j.done || !HasObservability(j.run)) continue;
    const lio::ScanResult* last = LastCalibration(j.run);
    if (last == nullptr) continue;
    any = true;
    const std::vector<std::string> names = CalibrationCoordinates(last->calibration);
    const std::vector<double> fraction = UnobservableFraction(j.run);
    const auto& c = last->calibration;
    for (size_t i = 0; i < names.size(); ++i) {
      csv << j.regime << ',' << j.index << ',' << j.method << ',' << names[i] << ',';
      WriteCoordinateObservability(c, i, csv);
      csv << ',' << (i < fraction.size() ? fraction[i] : NAN) << "\n";
    }
  }
  if (!any) return;
  io::WriteTextFile(out + "/observability.csv", csv.str());
  written->Add(out + "/observability.csv", "observability of every calibration coordinate per run");
}

}  // namespace ctlio::lioapp
