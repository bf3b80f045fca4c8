#include "lio/scoreboard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/checked_output.h"
#include "lio/run_odometry.h"

namespace ctlio::lioapp {

namespace {

std::map<std::string, std::string> ReadSettings(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open (not a ctlio_experiment output folder?)");
  std::map<std::string, std::string> kv;
  std::string key, value;
  while (f >> key >> value) kv[key] = value;
  return kv;
}

// The winner of a comparison where lower is better; `tolerance` is the printed resolution, below
// which the two are a tie rather than a win decided by noise in the last digit.
std::string Winner(double singer, double baseline, double tolerance, const std::string& a,
                   const std::string& b) {
  if (!std::isfinite(singer) && !std::isfinite(baseline)) return "tie";
  if (!std::isfinite(singer)) return b;
  if (!std::isfinite(baseline)) return a;
  if (std::abs(singer - baseline) <= tolerance) return "tie";
  return singer < baseline ? a : b;
}

std::string Cm(double metres) {
  char s[32];
  std::snprintf(s, sizeof(s), "%.2f", 100.0 * metres);
  return s;
}

}  // namespace

ScoreboardCellRuns ReadScoreboardCell(const std::string& dir) {
  const std::string settings_path = dir + "/settings.txt";
  const auto kv = ReadSettings(settings_path);
  ScoreboardCellRuns cell;
  if (kv.count("sensor")) {
    cell.sensor = kv.at("sensor");
  } else if (kv.count("config")) {
    cell.sensor = std::filesystem::path(kv.at("config")).stem().string();
  } else {
    throw std::runtime_error(settings_path + ": neither `sensor` nor `config` given");
  }
  if (!kv.count("world") || !kv.count("duration_s")) {
    throw std::runtime_error(settings_path + ": `world` or `duration_s` missing");
  }
  cell.world = kv.at("world");
  cell.duration_s = std::stod(kv.at("duration_s"));
  cell.rows = ReadResultsCsv(dir + "/results.csv");
  if (cell.rows.empty()) throw std::runtime_error(dir + "/results.csv: no runs");
  return cell;
}

MethodScore ScoreMethod(const std::vector<RunRow>& rows, const std::string& regime,
                        const std::string& method) {
  MethodScore s;
  s.method = method;
  double sum_sq = 0.0, drift = 0.0;
  int with_ate = 0, drift_n = 0;
  std::vector<double> median, p95;
  for (const RunRow& r : rows) {
    if (r.regime != regime || r.method != method || r.scenario != "none") continue;
    ++s.runs;
    if (r.failure) ++s.failed_runs;
    s.failed_scans += r.failed_scans;
    if (std::isfinite(r.ate_rmse_m)) {
      sum_sq += r.ate_rmse_m * r.ate_rmse_m;
      ++with_ate;
    }
    if (!r.failure && std::isfinite(r.drift_m_per_100m)) {
      drift += r.drift_m_per_100m;
      ++drift_n;
    }
    if (r.error.empty()) {
      median.push_back(r.median_cpu_ms);
      p95.push_back(r.p95_cpu_ms);
    }
  }
  if (s.runs == 0) throw std::runtime_error("no " + method + " run in regime " + regime);
  s.ate_rms_m = with_ate > 0 ? std::sqrt(sum_sq / with_ate) : NAN;
  s.drift_m_per_100m = drift_n > 0 ? drift / drift_n : NAN;
  s.cpu_median_ms = median.empty() ? NAN : Percentile(median, 0.5);
  s.cpu_p95_ms = p95.empty() ? NAN : Percentile(p95, 0.5);
  return s;
}

std::vector<ScoreboardRow> ScoreCells(const std::vector<ScoreboardCellRuns>& cells,
                                      const std::string& singer, const std::string& baseline) {
  std::vector<ScoreboardRow> out;
  for (const ScoreboardCellRuns& cell : cells) {
    std::vector<std::string> regimes;
    for (const RunRow& r : cell.rows) {
      if (std::find(regimes.begin(), regimes.end(), r.regime) == regimes.end()) {
        regimes.push_back(r.regime);
      }
    }
    for (const std::string& regime : regimes) {
      const std::string name = cell.sensor + "/" + cell.world + "/" + regime;
      std::map<std::string, std::set<int>> sequences;
      for (const RunRow& r : cell.rows) {
        if (r.regime == regime && r.scenario == "none") sequences[r.method].insert(r.sequence);
      }
      if (!sequences.count(singer) || !sequences.count(baseline)) {
        throw std::runtime_error("cell " + name + ": needs runs of both " + singer + " and " +
                                 baseline);
      }
      if (sequences.at(singer) != sequences.at(baseline)) {
        throw std::runtime_error("cell " + name + ": " + singer + " and " + baseline +
                                 " ran different sequences; the comparison would be unequal");
      }
      ScoreboardRow row;
      row.sensor = cell.sensor;
      row.world = cell.world;
      row.regime = regime;
      row.sequences.assign(sequences.at(singer).begin(), sequences.at(singer).end());
      row.singer = ScoreMethod(cell.rows, regime, singer);
      row.baseline = ScoreMethod(cell.rows, regime, baseline);
      row.cpu_ratio = row.singer.cpu_median_ms / row.baseline.cpu_median_ms;
      row.ate_winner = Winner(row.singer.ate_rms_m, row.baseline.ate_rms_m, 1e-5, singer, baseline);
      row.cpu_winner =
          Winner(row.singer.cpu_median_ms, row.baseline.cpu_median_ms, 0.05, singer, baseline);
      row.target_met = row.ate_winner != baseline && row.cpu_winner != baseline &&
                       row.singer.failed_scans == 0 && row.singer.failed_runs == 0;
      out.push_back(row);
    }
  }
  return out;
}

void WriteScoreboardCsv(const std::string& path, const std::vector<ScoreboardRow>& rows) {
  std::ofstream f = io::OpenForWriting(path);
  f << "sensor,world,regime,runs";
  for (const char* m : {"singer", "baseline"}) {
    f << ',' << m << "_ate_rms_m," << m << "_drift_m_per_100m," << m << "_failed_runs," << m
      << "_failed_scans," << m << "_cpu_median_ms," << m << "_cpu_p95_ms";
  }
  f << ",cpu_ratio,ate_winner,cpu_winner,target_met\n";
  for (const ScoreboardRow& r : rows) {
    char line[512];
    std::snprintf(line, sizeof(line), "%s,%s,%s,%d", r.sensor.c_str(), r.world.c_str(),
                  r.regime.c_str(), r.singer.runs);
    f << line;
    for (const MethodScore* m : {&r.singer, &r.baseline}) {
      std::snprintf(line, sizeof(line), ",%.6g,%.6g,%d,%d,%.4g,%.4g", m->ate_rms_m,
                    m->drift_m_per_100m, m->failed_runs, m->failed_scans, m->cpu_median_ms,
                    m->cpu_p95_ms);
      f << line;
    }
    std::snprintf(line, sizeof(line), ",%.4g,%s,%s,%d\n", r.cpu_ratio, r.ate_winner.c_str(),
                  r.cpu_winner.c_str(), r.target_met ? 1 : 0);
    f << line;
  }
  io::CloseChecked(f, path);
}

std::string ScoreboardMarkdown(const std::vector<ScoreboardRow>& rows) {
  std::ostringstream md;
  md << "| sensor | world | motion | runs | ATE [cm] Singer-LIO / baseline | drift per 100 m [m] "
        "S / B | failed runs (scans) S / B | CPU median [ms] S / B | CPU p95 [ms] S / B | CPU "
        "ratio S/B | ATE winner | CPU winner | target |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const auto short_name = [](const std::string& w) {
    return w == "singer_lio"  ? std::string("Singer-LIO")
           : w == "imu_input" ? std::string("baseline")
                              : w;
  };
  for (const ScoreboardRow& r : rows) {
    char line[600];
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %s | %d | %s / %s | %.3f / %.3f | %d (%d) / %d (%d) | %.1f / %.1f "
                  "| %.1f / %.1f | %.2f | %s | %s | %s |\n",
                  r.sensor.c_str(), r.world.c_str(), r.regime.c_str(), r.singer.runs,
                  Cm(r.singer.ate_rms_m).c_str(), Cm(r.baseline.ate_rms_m).c_str(),
                  r.singer.drift_m_per_100m, r.baseline.drift_m_per_100m, r.singer.failed_runs,
                  r.singer.failed_scans, r.baseline.failed_runs, r.baseline.failed_scans,
                  r.singer.cpu_median_ms, r.baseline.cpu_median_ms, r.singer.cpu_p95_ms,
                  r.baseline.cpu_p95_ms, r.cpu_ratio, short_name(r.ate_winner).c_str(),
                  short_name(r.cpu_winner).c_str(), r.target_met ? "met" : "**not met**");
    md << line;
  }
  return md.str();
}

std::string ScoreboardSummary(const std::vector<ScoreboardRow>& rows) {
  int met = 0, ate = 0, cpu = 0, singer_failed = 0, baseline_failed = 0, runs = 0;
  for (const ScoreboardRow& r : rows) {
    met += r.target_met;
    ate += r.ate_winner != r.baseline.method;
    cpu += r.cpu_winner != r.baseline.method;
    singer_failed += r.singer.failed_runs;
    baseline_failed += r.baseline.failed_runs;
    runs += r.singer.runs;
  }
  std::ostringstream s;
  const size_t n = rows.size();
  s << "Target met (Singer-LIO ATE ≤ baseline, CPU median ≤ baseline, 0 failed scans) in " << met
    << " of " << n << " cells; Singer-LIO's ATE ≤ the baseline's in " << ate << " of " << n
    << ", its CPU ≤ in " << cpu << " of " << n << "; failed runs Singer-LIO " << singer_failed
    << ", baseline " << baseline_failed << " (of " << runs << " each).";
  return s.str();
}

}  // namespace ctlio::lioapp
