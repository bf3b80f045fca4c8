// ctlio_geometry_report: the local-geometry statistic (planar / scattered fractions, median range;
// apps/eval geometry_statistics.h) of sweeps of any recording the readers open, or of point files.
//
//   ctlio_geometry_report --dataset=/data/newer_college/06_dynamic_spinning [--scans=2] [--first=0]
//   ctlio_geometry_report --cloud=deskewed_00.bin,deskewed_01.bin --bin_floats=3
//   ctlio_geometry_report --dataset=/tmp/sim_folder --scans=3 --every=50
// Simulated sequences without writing them: ctlio_simulate --geometry_report=0,50 (same table).
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <filesystem>
#include <iostream>

#include "common/command_line.h"
#include "ctlio/eval/geometry_statistics.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/point_cloud_io.h"

DEFINE_string(
    dataset, "",
    "A recording the readers open: a Newer College 2020, ctlio simulator or KITTI folder, "
    "or a ROS 1 bag");
DEFINE_string(cloud, "", "Point files instead (.pcd, .ply, .bin), comma separated: one sweep each");
DEFINE_int32(bin_floats, 4,
             "Floats per point of .bin files: 4 = KITTI (x y z reflectance), 3 = x y z");
DEFINE_int32(scans, 2, "--dataset: how many sweeps to report");
DEFINE_int32(first, 0, "--dataset: the first sweep reported (0-based)");
DEFINE_int32(every, 1, "--dataset: report every n-th sweep from --first");
DEFINE_double(min_range, 1.0, "Points closer than this are left out [m]");
DEFINE_double(max_range, 60.0, "Points farther than this are left out [m]");
DEFINE_double(voxel, 0.2, "Voxel edge of the downsampling [m]");
DEFINE_int32(neighbours, 10, "Nearest neighbours of each neighbourhood (the point included)");

constexpr char kUsage[] =
    "ctlio_geometry_report: how planar and how scattered the sweeps of a recording are (points\n"
    "1-60 m, 0.2 m voxels, eigenvalues of the 10 nearest neighbours' covariance).\n"
    "\n"
    "  ctlio_geometry_report --dataset=/data/newer_college/06_dynamic_spinning --scans=2\n"
    "  ctlio_geometry_report --cloud=deskewed_00.bin,deskewed_01.bin --bin_floats=3";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  try {
    using namespace ctlio;
    using ctlio::apps::RequireInRange;
    if (FLAGS_dataset.empty() == FLAGS_cloud.empty()) {
      throw std::invalid_argument("give exactly one of --dataset and --cloud");
    }
    RequireInRange("scans", FLAGS_scans, 1, 1'000'000);
    RequireInRange("first", FLAGS_first, 0, 100'000'000);
    RequireInRange("every", FLAGS_every, 1, 1'000'000);
    RequireInRange("bin_floats", FLAGS_bin_floats, 3, 64);
    RequireInRange("neighbours", FLAGS_neighbours, 3, 1000);
    RequireInRange("voxel", FLAGS_voxel, 1e-3, 100.0, " m");
    RequireInRange("min_range", FLAGS_min_range, 0.0, 1e4, " m");
    RequireInRange("max_range", FLAGS_max_range, FLAGS_min_range, 1e5, " m");
    eval::GeometryOptions options;
    options.min_range = FLAGS_min_range;
    options.max_range = FLAGS_max_range;
    options.voxel = FLAGS_voxel;
    options.neighbours = FLAGS_neighbours;
    if (!FLAGS_cloud.empty()) {
      bool header = false;
      for (const std::string& path : apps::SplitList(FLAGS_cloud)) {
        const std::string ext = std::filesystem::path(path).extension().string();
        const io::PointCloud cloud =
            ext == ".bin" ? io::ReadKittiBin(path, FLAGS_bin_floats) : io::ReadPointCloud(path);
        if (!header) eval::WriteGeometryHeader(std::cout);
        header = true;
        eval::WriteGeometryRow(std::cout, std::filesystem::path(path).filename().string(),
                               eval::ComputeGeometryStatistics(cloud.points, options));
      }
      return 0;
    }
    const auto source = io::OpenDataset(FLAGS_dataset);
    eval::WriteGeometryHeader(std::cout);
    io::ScanFrame frame;
    int reported = 0;
    for (size_t k = 0; reported < FLAGS_scans && source->Next(&frame); ++k) {
      if (k < size_t(FLAGS_first) || (k - size_t(FLAGS_first)) % size_t(FLAGS_every) != 0) {
        continue;
      }
      eval::WriteGeometryRow(std::cout, "scan " + std::to_string(k),
                             eval::ComputeGeometryStatistics(frame.cloud.points, options));
      ++reported;
    }
    if (reported < FLAGS_scans) {
      std::cerr << "ctlio_geometry_report: " << source->Name() << " has only " << reported
                << " of the " << FLAGS_scans << " sweeps asked for\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "ctlio_geometry_report: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
