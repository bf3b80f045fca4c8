// ctlio_odometry --save_map: where each method's map and its picture go, and the picture
// (tools/plot_map.py). The map itself is MapAccumulator's (map_accumulator.h), written by
// io::WriteMapCloud (ctlio/io/map_cloud_io.h).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "lio/map_accumulator.h"

namespace ctlio::lioapp {

// The --save_map flags checked before the run: FILE ends in .pcd or .ply, an absolute FILE's
// folder exists, --map_voxel_size is finite and > 0, --map_max_points ≥ 0. Throws
// std::runtime_error naming the flag.
void CheckMapFlags(const std::string& file, double voxel_size, int64_t max_points);

// The map file of a method: a relative `file` inside the method's output folder `out` (the
// --out folder with one method, --out/<method> with several); an absolute one as it is with one
// method, and with several with "_<method>" before the extension (/maps/run.pcd →
// /maps/run_imu_input.pcd), so that no method overwrites another's.
std::string MapPath(const std::string& file, const std::string& out, const std::string& method,
                    bool several_methods);

// The picture beside the map: its path with the extension replaced by .png.
std::string MapPicturePath(const std::string& map_path);

// Runs `python` (with matplotlib) on tools/plot_map.py: top view of the map at `map_path`,
// coloured by height, with the trajectory of `tum_path` on it, into `png_path`. False (and the
// script's message on stderr) if it failed.
bool PlotMap(const std::string& python, const std::string& tools_dir, const std::string& map_path,
             const std::string& tum_path, const std::string& png_path, double voxel_size,
             const std::string& title);

// The end of a --save_map run: writes `map` to `path` (io::WriteMapCloud; throws naming the
// path), its figures into `ev` (evaluation.txt: map_file, map_points, map_voxel_size_m,
// map_points_added, map_points_dropped_cap, map_peak_mb) and one line on stderr; with `plot`
// the picture MapPicturePath(path) drawn by `python` (empty: none has matplotlib, said on
// stderr) with the trajectory of `tum_path`.
void WriteMap(const MapAccumulator& map, const std::string& path, const std::string& tum_path,
              bool plot, const std::string& python, const std::string& tools_dir,
              const std::string& title, std::ostream& ev);

}  // namespace ctlio::lioapp
