#include "lio/map_output.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/map_cloud_io.h"

namespace ctlio::lioapp {

namespace {

// A shell word: single quotes, with every ' inside closed, escaped and reopened.
std::string Quoted(const std::string& s) {
  std::string q = "'";
  for (const char c : s) {
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return q + "'";
}

}  // namespace

void CheckMapFlags(const std::string& file, double voxel_size, int64_t max_points) {
  try {
    io::MapFormatOf(file);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("--save_map ") + e.what());
  }
  const std::filesystem::path p(file);
  if (p.is_absolute() && !std::filesystem::is_directory(p.parent_path())) {
    throw std::runtime_error("--save_map " + file + ": folder " + p.parent_path().string() +
                             " does not exist");
  }
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size)) {
    throw std::runtime_error("--map_voxel_size must be a finite number > 0 [m]");
  }
  if (max_points < 0) {
    throw std::runtime_error("--map_max_points must be >= 0 (0 = no cap)");
  }
}

std::string MapPath(const std::string& file, const std::string& out, const std::string& method,
                    bool several_methods) {
  const std::filesystem::path p(file);
  if (p.is_relative()) {
    return (std::filesystem::path(out) / p).string();
  }
  if (!several_methods) {
    return file;
  }
  std::filesystem::path named = p.parent_path() / (p.stem().string() + "_" + method);
  named += p.extension();
  return named.string();
}

std::string MapPicturePath(const std::string& map_path) {
  return std::filesystem::path(map_path).replace_extension(".png").string();
}

bool PlotMap(const std::string& python, const std::string& tools_dir, const std::string& map_path,
             const std::string& tum_path, const std::string& png_path, double voxel_size,
             const std::string& title) {
  std::ostringstream cmd;
  cmd << python << ' ' << Quoted(tools_dir + "/plot_map.py") << ' ' << Quoted(map_path) << ' '
      << Quoted(tum_path) << ' ' << Quoted(png_path) << " --voxel " << voxel_size << " --title "
      << Quoted(title) << " >/dev/null";
  return std::system(cmd.str().c_str()) == 0;
}

void WriteMap(const MapAccumulator& map, const std::string& path, const std::string& tum_path,
              bool plot, const std::string& python, const std::string& tools_dir,
              const std::string& title, std::ostream& ev) {
  io::WriteMapCloud(path, map.Points());
  const double mb = 1.0 / (1024.0 * 1024.0);
  ev << "map_file \"" << path << "\"\nmap_points " << map.size() << "\nmap_voxel_size_m "
     << map.voxel_size() << "\nmap_points_added " << map.added_points()
     << "\nmap_points_dropped_cap " << map.dropped_points() << "\nmap_peak_mb "
     << static_cast<double>(map.peak_bytes()) * mb << "\n";
  std::fprintf(stderr,
               "map: %zu points (%g m voxels, from %zu; %zu dropped at --map_max_points), file "
               "%.1f MB, voxel table peak %.1f MB: %s\n",
               map.size(), map.voxel_size(), map.added_points(), map.dropped_points(),
               double(std::filesystem::file_size(path)) * mb,
               static_cast<double>(map.peak_bytes()) * mb, path.c_str());
  if (!plot) {
    return;
  }
  const std::string png = MapPicturePath(path);
  if (python.empty()) {
    std::fprintf(stderr, "map: no python3 with matplotlib, no picture %s\n", png.c_str());
  } else if (!PlotMap(python, tools_dir, path, tum_path, png, map.voxel_size(), title)) {
    std::fprintf(stderr, "map: tools/plot_map.py failed, no picture %s\n", png.c_str());
  } else {
    std::fprintf(stderr, "map: picture %s\n", png.c_str());
  }
}

}  // namespace ctlio::lioapp
