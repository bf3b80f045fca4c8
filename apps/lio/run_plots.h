// The plots of a ctlio_odometry run: tools/plot_odometry.py (and plot_calibration.py where a
// calibration ran) through a python3 with matplotlib, and the list of the plot files a run made.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "lio/output_files.h"

namespace ctlio::lioapp {

// `python` if not empty, else the first of python3, /usr/bin/python3 that imports matplotlib;
// empty if none. Probed once per process (each probe starts a python, and the plots and every
// method's map ask).
std::string PythonWithMatplotlib(const std::string& python);

// Runs <tools_dir>/plot_odometry.py on `out` and the method folders, and plot_calibration.py on
// each folder with a calibration.csv; false if `python` is empty or a script failed.
bool PlotRuns(const std::string& python, const std::string& tools_dir, const std::string& out,
              const std::vector<std::string>& folders);

// Adds to `files` the plots written since `run_start` (not those an earlier run left in the
// folders): each folder's odometry.png, calibration.png, trajectory_topview.svg and, with several
// folders, out/comparison.png.
void ListPlots(const std::string& out, const std::vector<std::string>& folders,
               std::filesystem::file_time_type run_start, OutputFiles* files);

}  // namespace ctlio::lioapp
