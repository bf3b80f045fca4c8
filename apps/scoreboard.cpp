// ctlio_scoreboard: the project's scoreboard (docs/experiments/scoreboard.md) from ctlio_experiment
// cell folders (one per sensor × world × motion, each run with the sensor's shipped config):
// OUT/scoreboard.csv (one line per cell, both methods side by side) and OUT/scoreboard.md (the
// table with a header that records the settings, REDUCED when fewer than 10 sequences or shorter
// than 20 s were run). scripts/scoreboard.sh runs the cells and calls this; the plot is
// tools/plot_scoreboard.py.
//
//   ctlio_scoreboard --cells /tmp/sb/cells/vlp16_park_walking,/tmp/sb/cells/os1_64_quad_walking \
//                    --out /tmp/sb
#include "lio/scoreboard.h"

#include <gflags/gflags.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>

#include "common/command_line.h"
#include "ctlio/io/checked_output.h"

DEFINE_string(cells, "", "Comma-separated ctlio_experiment output folders, one per cell");
DEFINE_string(
    cells_under, "",
    "A folder whose sub-folders with a results.csv are the cells (sorted by name); with or "
    "instead of --cells");
DEFINE_string(out, "", "Output folder (required)");
DEFINE_string(note, "", "A line for the table's header (e.g. the command and a reduction)");

constexpr char kUsage[] =
    "ctlio_scoreboard: pools ctlio_experiment cell folders (sensor x world x motion) into one\n"
    "Singer-LIO vs baseline table: OUT/scoreboard.csv and OUT/scoreboard.md.\n"
    "\n"
    "  ctlio_scoreboard --cells_under /tmp/sb/cells --out /tmp/sb   # scripts/scoreboard.sh";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  using namespace ctlio::lioapp;
  try {
    if (FLAGS_out.empty()) throw std::runtime_error("--out is required");
    std::vector<std::string> dirs = ctlio::apps::SplitList(FLAGS_cells);
    if (!FLAGS_cells_under.empty()) {
      if (!std::filesystem::is_directory(FLAGS_cells_under)) {
        throw std::runtime_error("--cells_under: " + FLAGS_cells_under + " is not a folder");
      }
      std::vector<std::string> found;
      for (const auto& e : std::filesystem::directory_iterator(FLAGS_cells_under)) {
        if (!e.is_directory()) continue;
        // An interrupted cell (scripts/scoreboard.sh's CELL.tmp) has no results.csv yet.
        if (!std::filesystem::exists(e.path() / "results.csv")) {
          std::fprintf(stderr, "ctlio_scoreboard: skipped %s (no results.csv: unfinished)\n",
                       e.path().string().c_str());
          continue;
        }
        found.push_back(e.path().string());
      }
      std::sort(found.begin(), found.end());
      dirs.insert(dirs.end(), found.begin(), found.end());
    }
    if (dirs.empty()) throw std::runtime_error("no cells: give --cells or --cells_under");
    std::vector<ScoreboardCellRuns> cells;
    for (const auto& d : dirs) cells.push_back(ReadScoreboardCell(d));
    const std::vector<ScoreboardRow> rows = ScoreCells(cells);

    // The header: what was run, so that a reduced table is never taken for the full one.
    std::set<std::vector<int>> index_sets;
    std::set<double> durations;
    for (const auto& c : cells) durations.insert(c.duration_s);
    size_t fewest = 1 << 30;
    for (const auto& r : rows) {
      index_sets.insert(r.sequences);
      fewest = std::min(fewest, r.sequences.size());
    }
    std::ostringstream md;
    md << "# Scoreboard: Singer-LIO vs the IMU-as-input baseline, shipped per-sensor configs\n\n";
    md << rows.size() << " cells; sequences per cell: ";
    for (auto it = index_sets.begin(); it != index_sets.end(); ++it) {
      md << (it == index_sets.begin() ? "" : " | ") << "indices " << it->front() << "–"
         << it->back() << " (" << it->size() << ")";
    }
    md << "; duration";
    for (const double d : durations) md << ' ' << d << " s";
    const bool full = fewest >= 10 && *durations.begin() >= 20.0;
    md << (full ? ". Full scoreboard settings (10 × 20 s per cell).\n"
                : ". **REDUCED** (the full scoreboard: 10 sequences × 20 s per cell).\n");
    if (!FLAGS_note.empty()) md << "\n" << FLAGS_note << "\n";
    md << "\n"
       << ScoreboardMarkdown(rows) << "\n"
       << ScoreboardSummary(rows) << "\n\n"
       << "ATE: RMS over the runs of each run's RMSE ATE (failed runs included); drift: mean over "
          "the non-failed runs; CPU: the odometry thread's CPU per scan, median over the runs of "
          "each run's median (p95); target: Singer-LIO's ATE ≤ the baseline's, its CPU median ≤ "
          "the baseline's and 0 failed scans (ties within 0.01 mm / 0.05 ms count for "
          "Singer-LIO).\n";
    std::filesystem::create_directories(FLAGS_out);
    WriteScoreboardCsv(FLAGS_out + "/scoreboard.csv", rows);
    ctlio::io::WriteTextFile(FLAGS_out + "/scoreboard.md", md.str());
    std::cout << md.str() << "\nFiles written:\n  " << FLAGS_out
              << "/scoreboard.csv  one line per cell (CSV)\n  " << FLAGS_out
              << "/scoreboard.md   the table above (Markdown)\n";
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ctlio_scoreboard: %s\n", e.what());
    return 2;
  }
}
