#include "lio/run_plots.h"

#include <cstdlib>
#include <system_error>
#include <utility>

namespace ctlio::lioapp {

std::string PythonWithMatplotlib(const std::string& python) {
  static const std::string found = [&python] {
    std::string p = python;
    for (const char* candidate : {"python3", "/usr/bin/python3"}) {
      if (!p.empty()) break;
      const std::string probe = std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1";
      if (std::system(probe.c_str()) == 0) p = candidate;
    }
    return p;
  }();
  return found;
}

bool PlotRuns(const std::string& python, const std::string& tools_dir, const std::string& out,
              const std::vector<std::string>& folders) {
  if (python.empty()) return false;
  std::string cmd = python + " '" + tools_dir + "/plot_odometry.py' '" + out + "'";
  for (const std::string& f : folders) cmd += " '" + f + "'";
  bool ok = std::system((cmd + " >/dev/null").c_str()) == 0;
  // The online calibration's estimates and ±3σ over time (calibration.png per method folder).
  for (const std::string& f : folders) {
    if (!std::filesystem::exists(f + "/calibration.csv")) continue;
    const std::string c = python + " '" + tools_dir + "/plot_calibration.py' '" + f + "'";
    ok = std::system((c + " >/dev/null").c_str()) == 0 && ok;
  }
  return ok;
}

void ListPlots(const std::string& out, const std::vector<std::string>& folders,
               std::filesystem::file_time_type run_start, OutputFiles* files) {
  const auto made = [&](const std::string& path) {
    std::error_code error;
    return std::filesystem::exists(path, error) &&
           std::filesystem::last_write_time(path, error) >= run_start;
  };
  for (const std::string& f : folders) {
    for (const auto& [name, what] :
         {std::pair<const char*, const char*>{"odometry.png",
                                              "plot: trajectory, errors, scan times"},
          {"calibration.png", "plot: calibration estimates, ±3σ"},
          {"trajectory_topview.svg", "plot: top view (no matplotlib)"}}) {
      if (made(f + "/" + name)) files->Add(f + "/" + name, what);
    }
  }
  if (folders.size() > 1 && made(out + "/comparison.png")) {
    files->Add(out + "/comparison.png", "plot: the methods side by side");
  }
}

}  // namespace ctlio::lioapp
