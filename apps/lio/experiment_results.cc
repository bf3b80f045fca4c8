#include "lio/experiment_results.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/checked_output.h"
#include "lio/run_odometry.h"

namespace ctlio::lioapp {

namespace {

const char* kHeader =
    "regime,sequence,method,scenario,ate_rmse_m,ate_pairs,failed_scans,degenerate_scans,"
    "imu_gap_scans,failure,median_ms,p95_ms,max_ms,median_cpu_ms,p95_cpu_ms,drift_m_per_100m,"
    "scans,degenerate_direction_scans,error";
constexpr int kFields = 19;

// Position of `key` in `order`, appended when new: the order of first appearance.
void Remember(std::vector<std::string>* order, const std::string& key) {
  if (std::find(order->begin(), order->end(), key) == order->end()) order->push_back(key);
}

double ParseDouble(const std::string& s, const std::string& where) {
  if (s == "nan" || s == "-nan") return std::numeric_limits<double>::quiet_NaN();
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || s.empty()) throw std::runtime_error(where + ": bad number '" + s + "'");
  return v;
}

}  // namespace

void WriteResultsCsv(const std::string& path, const std::vector<RunRow>& rows) {
  std::ofstream f = io::OpenForWriting(path);
  f << kHeader << '\n' << std::setprecision(17);
  for (const RunRow& r : rows) {
    std::string error;
    for (const char c : r.error) error += (c == '"') ? std::string("\"\"") : std::string(1, c);
    f << r.regime << ',' << r.sequence << ',' << r.method << ',' << r.scenario << ','
      << r.ate_rmse_m << ',' << r.ate_pairs << ',' << r.failed_scans << ',' << r.degenerate_scans
      << ',' << r.imu_gap_scans << ',' << (r.failure ? 1 : 0) << ',' << r.median_ms << ','
      << r.p95_ms << ',' << r.max_ms << ',' << r.median_cpu_ms << ',' << r.p95_cpu_ms << ','
      << r.drift_m_per_100m << ',' << r.scans << ',' << r.degenerate_direction_scans << ",\""
      << error << "\"\n";
  }
  io::CloseChecked(f, path);
}

std::vector<RunRow> ReadResultsCsv(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open the results");
  std::string line;
  if (!std::getline(f, line) || line != kHeader) {
    throw std::runtime_error(path + ":1: not a results file of this version (expected header '" +
                             std::string(kHeader) + "')");
  }
  std::vector<RunRow> rows;
  for (int n = 2; std::getline(f, line); ++n) {
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(n);
    std::vector<std::string> v;
    size_t pos = 0;
    while (static_cast<int>(v.size()) < kFields - 1) {
      const size_t comma = line.find(',', pos);
      if (comma == std::string::npos) break;
      v.push_back(line.substr(pos, comma - pos));
      pos = comma + 1;
    }
    std::string error = line.substr(std::min(pos, line.size()));
    if (static_cast<int>(v.size()) != kFields - 1 || error.size() < 2 || error.front() != '"' ||
        error.back() != '"') {
      throw std::runtime_error(where + ": expected " + std::to_string(kFields) +
                               " comma-separated fields, the last one quoted");
    }
    RunRow r;
    r.regime = v[0];
    r.sequence = static_cast<int>(ParseDouble(v[1], where));
    r.method = v[2];
    r.scenario = v[3];
    r.ate_rmse_m = ParseDouble(v[4], where);
    r.ate_pairs = static_cast<size_t>(ParseDouble(v[5], where));
    r.failed_scans = static_cast<int>(ParseDouble(v[6], where));
    r.degenerate_scans = static_cast<int>(ParseDouble(v[7], where));
    r.imu_gap_scans = static_cast<int>(ParseDouble(v[8], where));
    r.failure = ParseDouble(v[9], where) != 0.0;
    r.median_ms = ParseDouble(v[10], where);
    r.p95_ms = ParseDouble(v[11], where);
    r.max_ms = ParseDouble(v[12], where);
    r.median_cpu_ms = ParseDouble(v[13], where);
    r.p95_cpu_ms = ParseDouble(v[14], where);
    r.drift_m_per_100m = ParseDouble(v[15], where);
    r.scans = static_cast<int>(ParseDouble(v[16], where));
    r.degenerate_direction_scans = static_cast<int>(ParseDouble(v[17], where));
    error = error.substr(1, error.size() - 2);
    for (size_t i = 0; i < error.size(); ++i) {
      r.error += error[i];
      if (error[i] == '"' && i + 1 < error.size() && error[i + 1] == '"') ++i;
    }
    rows.push_back(r);
  }
  return rows;
}

std::vector<PooledCell> PoolRows(const std::vector<RunRow>& rows) {
  std::vector<std::string> regimes, scenarios, methods;
  for (const RunRow& r : rows) {
    Remember(&regimes, r.regime);
    Remember(&scenarios, r.scenario);
    Remember(&methods, r.method);
  }
  std::vector<PooledCell> cells;
  for (const auto& regime : regimes) {
    for (const auto& scenario : scenarios) {
      for (const auto& method : methods) {
        PooledCell c{regime, method, scenario};
        double s_ok = 0, n_ok = 0, s_all = 0, n_all = 0, drift_sum = 0, drift_n = 0;
        std::vector<double> med, p95, cpu;
        for (const RunRow& r : rows) {
          if (r.regime != regime || r.method != method || r.scenario != scenario) continue;
          ++c.runs;
          if (r.failure) ++c.failures;
          if (!r.error.empty()) continue;
          c.scans += r.scans;
          c.degenerate_scans += r.degenerate_scans;
          c.degenerate_direction_scans += r.degenerate_direction_scans;
          if (!r.failure && std::isfinite(r.drift_m_per_100m)) {
            drift_sum += r.drift_m_per_100m;
            ++drift_n;
          }
          const double n = double(r.ate_pairs);
          const double e2 = r.ate_rmse_m * r.ate_rmse_m;
          if (n > 0 && std::isfinite(e2)) {
            s_all += n * e2;
            n_all += n;
            if (!r.failure) {
              s_ok += n * e2;
              n_ok += n;
            }
          }
          med.push_back(r.median_ms);
          p95.push_back(r.p95_ms);
          cpu.push_back(r.median_cpu_ms);
        }
        if (c.runs == 0) continue;
        c.rmse_ok = n_ok > 0 ? std::sqrt(s_ok / n_ok) : NAN;
        c.rmse_all = n_all > 0 ? std::sqrt(s_all / n_all) : NAN;
        c.drift_ok = drift_n > 0 ? drift_sum / drift_n : NAN;
        c.median_ms = Percentile(med, 0.5);
        c.p95_ms = Percentile(p95, 0.5);
        c.median_cpu_ms = Percentile(cpu, 0.5);
        cells.push_back(c);
      }
    }
  }
  return cells;
}

std::string PooledTableMarkdown(const std::vector<PooledCell>& cells) {
  std::ostringstream md;
  md << "| regime | method | scenario | runs | RMSE ATE (non-failed) [m] | RMSE ATE (all) [m] | "
        "drift per 100 m (non-failed, mean) [m] | failures | scans degenerate / degen_dir / all | "
        "median ms/scan (wall) | p95 ms/scan (wall) | median CPU ms/scan |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const PooledCell& c : cells) {
    char line[400];
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %s | %d | %.4f | %.4f | %.3f | %d | %d / %d / %d | %.1f | %.1f | "
                  "%.1f |\n",
                  c.regime.c_str(), c.method.c_str(), c.scenario.c_str(), c.runs, c.rmse_ok,
                  c.rmse_all, c.drift_ok, c.failures, c.degenerate_scans,
                  c.degenerate_direction_scans, c.scans, c.median_ms, c.p95_ms, c.median_cpu_ms);
    md << line;
  }
  return md.str();
}

void WritePooledCsv(const std::string& path, const std::vector<PooledCell>& cells) {
  std::ofstream f = io::OpenForWriting(path);
  f << "regime,method,scenario,runs,failures,rmse_ate_non_failed_m,rmse_ate_all_m,"
       "drift_m_per_100m_non_failed,scans,degenerate_scans,degenerate_direction_scans\n";
  for (const PooledCell& c : cells) {
    char line[400];
    std::snprintf(line, sizeof(line), "%s,%s,%s,%d,%d,%.6g,%.6g,%.6g,%d,%d,%d\n", c.regime.c_str(),
                  c.method.c_str(), c.scenario.c_str(), c.runs, c.failures, c.rmse_ok, c.rmse_all,
                  c.drift_ok, c.scans, c.degenerate_scans, c.degenerate_direction_scans);
    f << line;
  }
  io::CloseChecked(f, path);
}

std::string CentimetreLabel(double metres) {
  std::ostringstream s;
  s << std::setprecision(2) << 100.0 * metres;
  return s.str();
}

}  // namespace ctlio::lioapp
