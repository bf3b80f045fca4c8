// icp_pairs: pairwise point-to-point ICP (apps/eval point_icp.h) on real sweeps with reference
// poses and on simulated sweeps with ground truth, for docs/experiments/worlds-geometry.md.
// Every pair starts from the reference relative pose perturbed by 0.3 m, 0.2 m and 2° of yaw;
// the error of the converged pose against the reference is printed.
//
//   icp_pairs real <graph.txt> <sweep 0> <sweep 1> ...   (float32 x y z files; a+b joins two)
//   icp_pairs sim <preset> <world> <world_seed> <index> <first scan> <gap> <pairs> [deskew]
// With `deskew` the simulated sweeps are first motion-corrected with the ground truth into the
// lidar frame at the middle of the sweep (as the real Newer College sweeps and features are).
//
//   icp_pairs seq <preset> <world> <world_seed> <index> <first scan> <scans> <window> [nodeskew]
// runs the point-to-point odometry (point_odometry.h: constant-velocity prediction and deskew,
// local voxel map) over raw simulated sweeps, started at the true pose of the first, and prints
// the drift (final error over the path length) and the relative error over every `window`
// consecutive sweeps (the spacing of the real keyframe pairs), as a % of the distance. It starts
// with the true motion of the first two sweeps. Environment (experiments): ICP_GATES=g (gates g,
// g/2 instead of 2, 1, 0.5 m), ICP_NO_EFFECTS=1 (the preset without its sensor effects).
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "ctlio/eval/point_icp.h"
#include "ctlio/eval/point_odometry.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"

namespace {

using namespace ctlio;

std::vector<Vec3> ReadSweep(const std::string& spec) {
  std::vector<Vec3> out;
  std::stringstream ss(spec);
  for (std::string f; std::getline(ss, f, '+');) {
    const io::PointCloud c = io::ReadKittiBin(f, 3);
    out.insert(out.end(), c.points.begin(), c.points.end());
  }
  return out;
}

double total_t = 0.0, total_r = 0.0, total_d = 0.0;
int pairs = 0;

void Pair(const std::string& label, const std::vector<Vec3>& target,
          const std::vector<Vec3>& source, const SE3& truth) {
  Vec6 kick;
  kick << 0.3, 0.2, 0.0, 0.0, 0.0, 2.0 * M_PI / 180.0;
  const eval::PointIcpResult r = eval::RegisterPointToPoint(source, target, truth * SE3::Exp(kick));
  const SE3 e = truth.Inverse() * r.target_from_source;
  const double et = e.translation().norm(), er = e.Log().tail<3>().norm() * 180.0 / M_PI;
  std::printf("%-36s distance %6.2f m  error %6.3f m  %5.2f deg  (%d correspondences)\n",
              label.c_str(), truth.translation().norm(), et, er, r.correspondences);
  total_t += et;
  total_r += er;
  total_d += truth.translation().norm();
  ++pairs;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "real" && argc >= 5) {
      std::ifstream g(argv[2]);
      std::vector<SE3> poses;
      for (std::string line; std::getline(g, line);) {
        std::istringstream in(line);
        std::string id;
        double x, y, z, qx, qy, qz, qw;
        if (in >> id >> x >> y >> z >> qx >> qy >> qz >> qw) {
          poses.push_back(SE3(Eigen::Quaterniond(qw, qx, qy, qz), Vec3(x, y, z)));
        }
      }
      for (int k = 3; k + 1 < argc && k - 2 < int(poses.size()); ++k) {
        const SE3 truth = poses[k - 3].Inverse() * poses[k - 2];
        Pair(std::string(argv[k + 1]).substr(std::string(argv[k + 1]).find_last_of('/') + 1),
             ReadSweep(argv[k]), ReadSweep(argv[k + 1]), truth);
      }
    } else if (mode == "sim" && (argc == 9 || (argc == 10 && std::string(argv[9]) == "deskew"))) {
      const bool deskew = argc == 10;
      sim::SimConfig c = sim::PresetConfig(sim::ParsePreset(argv[2]), std::stoi(argv[5]));
      c.world.kind = sim::ParseWorld(argv[3]);
      c.world.seed = std::stoull(argv[4]);
      const int first = std::stoi(argv[6]), gap = std::stoi(argv[7]), n = std::stoi(argv[8]);
      c.duration_s = 0.1 * (first + gap * n + 2);
      c.integration_step_s = 1e-3;
      const sim::LidarInertialSim sim(c);
      // The pose of a sweep: the lidar's at its middle (the sweeps are not deskewed).
      auto pose = [&](int k) { return sim.WorldFromLidar(sim.Seconds(sim.ScanStartNs(k)) + 0.05); };
      auto sweep = [&](int k) {
        io::PointCloud c = sim.Scan(k);
        if (deskew) {
          const SE3 mid_inv = pose(k).Inverse();
          for (size_t i = 0; i < c.size(); ++i) {
            c.points[i] = mid_inv * (sim.WorldFromLidar(sim.Seconds(c.times_ns[i])) * c.points[i]);
          }
        }
        return c.points;
      };
      for (int j = 0; j < n; ++j) {
        const int a = first + j * gap, b = a + gap;
        Pair(std::string(argv[3]) + " sweeps " + std::to_string(a) + "-" + std::to_string(b),
             sweep(a), sweep(b), pose(a).Inverse() * pose(b));
      }
    } else if (mode == "seq" && (argc == 9 || (argc == 10 && std::string(argv[9]) == "nodeskew"))) {
      sim::SimOverrides overrides;
      if (std::getenv("ICP_NO_EFFECTS")) overrides.sensor_effects = "off";
      sim::SimConfig c = sim::PresetConfig(sim::ParsePreset(argv[2]), std::stoi(argv[5]),
                                           sim::kExperimentSeed, overrides);
      c.world.kind = sim::ParseWorld(argv[3]);
      c.world.seed = std::stoull(argv[4]);
      const int first = std::stoi(argv[6]), n = std::stoi(argv[7]), window = std::stoi(argv[8]);
      c.duration_s = 0.1 * (first + n + 2);
      c.integration_step_s = 1e-3;
      const sim::LidarInertialSim sim(c);
      const double period = 1.0 / c.lidar.rate_hz;
      auto mid = [&](int k) { return sim.Seconds(sim.ScanStartNs(k)) + 0.5 * period; };
      std::vector<SE3> truth;
      for (int k = first; k < first + n; ++k) truth.push_back(sim.WorldFromLidar(mid(k)));
      eval::PointOdometryOptions options;
      options.deskew = argc == 9;
      options.max_range = std::min(100.0, c.lidar.max_range);
      if (const char* g = std::getenv("ICP_GATES"))
        options.gates = {std::atof(g), 0.5 * std::atof(g)};
      // Started in motion: the true relative motion of the first two sweeps as the initial
      // constant velocity (the odometry cannot know it from one sweep).
      eval::PointOdometry odometry(truth.front(), options, truth[0].Inverse() * truth[1]);
      double cpu = 0.0;
      for (int k = first; k < first + n; ++k) {
        const io::PointCloud cloud = sim.Scan(k);
        std::vector<double> times(cloud.size());
        for (size_t i = 0; i < cloud.size(); ++i)
          times[i] = sim.Seconds(cloud.times_ns[i]) - mid(k);
        const std::clock_t c0 = std::clock();
        odometry.Register(cloud.points, times, period);
        cpu += double(std::clock() - c0) / CLOCKS_PER_SEC;
      }
      const std::vector<SE3>& est = odometry.poses();
      double path = 0.0;
      for (int k = 1; k < n; ++k)
        path += (truth[k].translation() - truth[k - 1].translation()).norm();
      const double final_error = (est.back().translation() - truth.back().translation()).norm();
      double rel_t = 0.0, rel_r = 0.0, rel_d = 0.0;
      int windows = 0;
      for (int k = 0; k + window < n; ++k) {
        const SE3 dt = truth[k].Inverse() * truth[k + window];
        const SE3 e = dt.Inverse() * (est[k].Inverse() * est[k + window]);
        rel_t += e.translation().norm();
        rel_r += e.Log().tail<3>().norm() * 180.0 / M_PI;
        rel_d += dt.translation().norm();
        ++windows;
      }
      std::printf(
          "%s %s seed %s index %s sweeps %d-%d%s: path %.1f m, final error %.3f m (%.2f %%); "
          "over %d windows of %d sweeps (mean %.2f m): %.3f m (%.2f %%), %.3f deg; %.0f ms CPU "
          "per sweep\n",
          argv[2], argv[3], argv[4], argv[5], first, first + n - 1,
          options.deskew ? "" : " (no deskew)", path, final_error, 100.0 * final_error / path,
          windows, window, rel_d / windows, rel_t / windows, 100.0 * rel_t / rel_d, rel_r / windows,
          1e3 * cpu / n);
      return 0;
    } else {
      std::cerr << "usage: icp_pairs real <graph.txt> <sweep>... | icp_pairs sim <preset> <world> "
                   "<world_seed> <index> <first> <gap> <pairs>\n";
      return 2;
    }
    std::printf("mean over %d pairs: distance %.2f m, error %.3f m (%.2f %%), %.2f deg\n", pairs,
                total_d / pairs, total_t / pairs, 100.0 * total_t / total_d, total_r / pairs);
  } catch (const std::exception& e) {
    std::cerr << "icp_pairs: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
