// icp_pairs: pairwise point-to-point ICP (apps/eval point_icp.h) on real sweeps with reference
// poses and on simulated sweeps with ground truth, for docs/experiments/worlds-geometry.md.
// Every pair starts from the reference relative pose perturbed by 0.3 m, 0.2 m and 2° of yaw;
// the error of the converged pose against the reference is printed.
//
//   icp_pairs real <graph.txt> <sweep 0> <sweep 1> ...   (float32 x y z files; a+b joins two)
// ICP_ALL_PAIRS=1 registers every pair i < j (non-adjacent keyframes: larger spacings), not only
// the consecutive ones; ICP_AXES=1 prints each pair's true rotation and its error per axis.
//   icp_pairs sim <preset> <world> <world_seed> <index> <first scan> <gap> <pairs> [deskew]
// With `deskew` the simulated sweeps are first motion-corrected with the ground truth into the
// lidar frame at the middle of the sweep (as the real Newer College sweeps and features are).
// Environment: ICP_NO_EFFECTS=1 (the preset without its sensor effects), ICP_EFFECT_ONLY=angles|
// range|footprint|mixed|grazing (one effect alone), ICP_FEATURES=1 (LOAM-like features of each
// sweep instead of all its points, as the real Newer College pairs are), ICP_EFFECT_DROP=a,b (the
// preset's effects without these), ICP_SHAKE_SCALE=s (as below), ICP_RELIEF=m / ICP_GRASS_RELIEF=m
// (the quad's and town's ground micro-relief), ICP_GROUND_CHECK=1 (no registration: the slope of
// each sweep's ground, deskewed with the truth, against the truth's vertical).
//
//   icp_pairs replay <preset> <world> <world_seed> <index> <places> <graph.txt> <sweep 0> ...
// Like with like: the real keyframes' relative poses (graph.txt) replayed in the simulated world.
// At each of `places` start places along the preset's path (its pose every 4 s from 2 s, levelled,
// turned so that the real keyframes' overall direction of travel is the path's), one sweep is
// simulated standing still at each real keyframe's pose (static sweeps: no motion within a sweep,
// as the real features are deskewed), and every pair i < j is registered as the real pair is,
// from the same perturbed start; LOAM-like features unless ICP_RAW=1; ICP_PLACE_GAP=s. Prints, per
// pair, the real error and the simulated ones over the places, and tests "sim drifts more" (exact
// one-sided sign and signed-rank tests). The effect overrides of `sim` apply (ICP_NO_EFFECTS, ...).
//
//   icp_pairs seq <preset> <world> <world_seed> <index> <first scan> <scans> <window> [nodeskew]
// runs the point-to-point odometry (point_odometry.h: constant-velocity prediction and deskew,
// local voxel map) over raw simulated sweeps, started at the true pose of the first, and prints
// the drift (final error over the path length) and the relative error over every `window`
// consecutive sweeps (the spacing of the real keyframe pairs), as a % of the distance. It starts
// with the true motion of the first two sweeps. Environment (experiments): ICP_FIXED_SIGMA=s (a
// fixed threshold σ instead of the adaptive one), ICP_NO_EFFECTS=1 (the preset without its sensor
// effects), ICP_TRUE_DESKEW=1 (sweeps deskewed with the truth), ICP_MAP_VOXEL=v (map voxel v,
// registration points 1.5·v), ICP_SHAKE_SCALE=s (the walk's or drive's fast rotations × s),
// ICP_TRUTH_ONLY=1 (only the truth's constant-velocity model error), ICP_VERBOSE=1 (per sweep),
// ICP_NO_NOISE=1 (no range noise), ICP_MIN_RANGE=r (points nearer than r [m] dropped; 1 m),
// ICP_STRIDE=s (every s-th sweep only: s times the step per registration), ICP_ABS=1 (the pose
// error of every sweep), ICP_MAX_POINTS=n (points per map voxel), ICP_MAX_RANGE=r (range and map
// radius), ICP_CONVERGED=c (the ICP's stopping step).
#include "icp_pairs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>

#include "ctlio/eval/point_icp.h"
#include "ctlio/eval/point_odometry.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "loam_features.h"

namespace ctlio::icp_pairs {

std::vector<Vec3> ReadSweep(const std::string& spec) {
  std::vector<Vec3> out;
  std::stringstream ss(spec);
  for (std::string f; std::getline(ss, f, '+');) {
    const io::PointCloud c = io::ReadKittiBin(f, 3);
    out.insert(out.end(), c.points.begin(), c.points.end());
  }
  return out;
}

// LOAM features of a sweep (loam_features.h: smoothness along each ring, capped per sector, the
// "less sharp" edges and "less flat" planes, as the real Newer College features are). With
// ICP_PROPORTIONAL_FEATURES=1 the earlier imitation of the real files' proportions instead: per
// ring the flattest 31 % and sharpest 2 % by |Σ_{j=−5..5} (p_{i+j} − p_i)| / |p_i|. Returns the
// indices kept.
// ICP_LOAM_LESS_SHARP=n: n edge points per sector at most instead of LOAM's 20 (the real files
// hold about 1.3 k edges per sweep, which the reference parameters do not give here).
LoamFeatureOptions LoamOptionsFromEnvironment() {
  LoamFeatureOptions o;
  if (const char* n = std::getenv("ICP_LOAM_LESS_SHARP")) {
    o.less_sharp_per_sector = std::atoi(n);
    if (o.less_sharp_per_sector < 0)
      throw std::invalid_argument("ICP_LOAM_LESS_SHARP must be a non-negative integer");
    o.sharp_per_sector = std::min(o.sharp_per_sector, o.less_sharp_per_sector);
  }
  return o;
}

std::vector<size_t> LoamLikeFeatures(const io::PointCloud& c) {
  if (std::getenv("ICP_PROPORTIONAL_FEATURES") == nullptr) {
    const LoamFeatures f = SelectLoamFeatures(c.points, c.ring, LoamOptionsFromEnvironment());
    std::vector<size_t> keep = f.edges;
    keep.insert(keep.end(), f.planes.begin(), f.planes.end());
    std::sort(keep.begin(), keep.end());
    return keep;
  }
  std::map<int, std::vector<size_t>> rings;
  for (size_t i = 0; i < c.size(); ++i) rings[c.ring.empty() ? 0 : c.ring[i]].push_back(i);
  std::vector<size_t> keep;
  for (const auto& [ring, idx] : rings) {
    std::vector<std::pair<double, size_t>> curv;
    for (size_t k = 5; k + 5 < idx.size(); ++k) {
      Vec3 d = Vec3::Zero();
      for (int j = -5; j <= 5; ++j) d += c.points[idx[k + j]] - c.points[idx[k]];
      curv.push_back({d.norm() / c.points[idx[k]].norm(), idx[k]});
    }
    std::sort(curv.begin(), curv.end());
    const size_t planes = size_t(0.31 * curv.size()), edges = size_t(0.02 * curv.size());
    for (size_t k = 0; k < planes; ++k) keep.push_back(curv[k].second);
    for (size_t k = curv.size() - edges; k < curv.size(); ++k) keep.push_back(curv[k].second);
  }
  std::sort(keep.begin(), keep.end());
  return keep;
}

// The world and motion overrides both simulated modes read: ICP_SHAKE_SCALE (the guided motion's
// fast rotations, pitch, roll and fast yaw, scaled: how much of an error they cause),
// ICP_RELIEF and ICP_GRASS_RELIEF (the quad's and town's ground micro-relief [m]).
void ApplyWorldOverrides(sim::SimConfig* c) {
  if (const char* m = std::getenv("ICP_SHAKE_SCALE")) {
    sim::GuideProfile& g = c->motion.guide;
    g.pitch.amplitude *= std::atof(m);
    g.roll.amplitude *= std::atof(m);
    g.yaw_fast.amplitude *= std::atof(m);
  }
  if (const char* r = std::getenv("ICP_RELIEF")) {
    c->world.town.vegetation.relief = c->world.quad.vegetation.relief = std::atof(r);
  }
  if (const char* r = std::getenv("ICP_GRASS_RELIEF")) {
    c->world.town.vegetation.grass_relief = c->world.quad.vegetation.grass_relief = std::atof(r);
  }
}

// The effect experiments both pairwise modes read: ICP_EFFECT_ONLY=angles|range|footprint|mixed|
// grazing (one of the preset's effects alone) and ICP_EFFECT_DROP=a,b (the preset's without these).
void ApplyEffectOverrides(sim::SimConfig* c) {
  if (const char* only = std::getenv("ICP_EFFECT_ONLY")) {
    // One of the preset's effects alone (the others off).
    const sim::SensorEffects e = c->lidar.effects;
    sim::SensorEffects& f = c->lidar.effects;
    f = sim::SensorEffects();
    const std::string o = only;
    if (o == "angles") {
      f.elevation_error_deg = e.elevation_error_deg;
      f.azimuth_error_deg = e.azimuth_error_deg;
    } else if (o == "range") {
      f.range_offset_sigma = e.range_offset_sigma;
    } else if (o == "footprint") {
      f.beam_divergence_rad = e.beam_divergence_rad;
    } else if (o == "mixed") {
      f.mixed_pixel_probability = e.mixed_pixel_probability;
      f.mixed_pixel_min_gap = e.mixed_pixel_min_gap;
    } else if (o == "grazing") {
      f.grazing_dropout_start_deg = e.grazing_dropout_start_deg;
    } else {
      throw std::invalid_argument("ICP_EFFECT_ONLY: angles|range|footprint|mixed|grazing");
    }
  }
  if (const char* drop = std::getenv("ICP_EFFECT_DROP")) {
    // The preset's effects without these (comma-separated, names as ICP_EFFECT_ONLY).
    sim::SensorEffects& f = c->lidar.effects;
    const std::string d = drop;
    if (d.find("angles") != std::string::npos) f.elevation_error_deg = f.azimuth_error_deg = 0;
    if (d.find("range") != std::string::npos) f.range_offset_sigma = 0;
    if (d.find("footprint") != std::string::npos) f.beam_divergence_rad = 0;
    if (d.find("mixed") != std::string::npos) f.mixed_pixel_probability = 0;
    if (d.find("grazing") != std::string::npos) f.grazing_dropout_start_deg = 90;
  }
}

namespace {
double total_t = 0.0, total_r = 0.0, total_d = 0.0;
int pairs = 0;
}  // namespace

// Registers source to target from `truth` perturbed; prints and returns the translation error [m].
double Pair(const std::string& label, const std::vector<Vec3>& target,
            const std::vector<Vec3>& source, const SE3& truth) {
  Vec6 kick;
  kick << 0.3, 0.2, 0.0, 0.0, 0.0, 2.0 * M_PI / 180.0;
  const eval::PointIcpResult r = eval::RegisterPointToPoint(source, target, truth * SE3::Exp(kick));
  const SE3 e = truth.Inverse() * r.target_from_source;
  const double et = e.translation().norm(), er = e.Log().tail<3>().norm() * 180.0 / M_PI;
  std::printf("%-36s distance %6.2f m  error %6.3f m  %5.2f deg  (%d correspondences)\n",
              label.c_str(), truth.translation().norm(), et, er, r.correspondences);
  if (std::getenv("ICP_AXES")) {
    const Vec6 l = e.Log();
    const Vec6 lt = truth.Log();
    std::printf("  true rot %+.3f %+.3f %+.3f deg", lt(3) * 180 / M_PI, lt(4) * 180 / M_PI,
                lt(5) * 180 / M_PI);
    std::printf("  axes: t %+.3f %+.3f %+.3f m  r %+.3f %+.3f %+.3f deg\n", e.translation().x(),
                e.translation().y(), e.translation().z(), l(3) * 180 / M_PI, l(4) * 180 / M_PI,
                l(5) * 180 / M_PI);
  }
  total_t += et;
  total_r += er;
  total_d += truth.translation().norm();
  ++pairs;
  return et;
}

// The keyframe poses of a gtsam_points graph.txt ("id x y z qx qy qz qw" per line).
std::vector<SE3> ReadGraph(const std::string& path) {
  std::ifstream g(path);
  if (!g) throw std::runtime_error("cannot open " + path);
  std::vector<SE3> poses;
  for (std::string line; std::getline(g, line);) {
    std::istringstream in(line);
    std::string id;
    double x, y, z, qx, qy, qz, qw;
    if (in >> id >> x >> y >> z >> qx >> qy >> qz >> qw) {
      poses.push_back(SE3(Eigen::Quaterniond(qw, qx, qy, qz), Vec3(x, y, z)));
    }
  }
  return poses;
}

}  // namespace ctlio::icp_pairs

using namespace ctlio;
using namespace ctlio::icp_pairs;

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "real" && argc >= 5) {
      const std::vector<SE3> poses = ReadGraph(argv[2]);
      // ICP_ALL_PAIRS=1: every pair i < j, not only the consecutive ones (non-adjacent pairs at
      // larger spacings).
      const bool all = std::getenv("ICP_ALL_PAIRS") != nullptr;
      const int sweeps = std::min(argc - 3, int(poses.size()));
      for (int i = 0; i + 1 < sweeps; ++i) {
        for (int j = i + 1; j < (all ? sweeps : i + 2); ++j) {
          const auto name = [&](int a) {
            const std::string f = argv[3 + a];
            return f.substr(f.find_last_of('/') + 1);
          };
          Pair(name(i) + " -> " + name(j), ReadSweep(argv[3 + i]), ReadSweep(argv[3 + j]),
               poses[i].Inverse() * poses[j]);
        }
      }
    } else if (mode == "sim" && (argc == 9 || (argc == 10 && std::string(argv[9]) == "deskew"))) {
      const bool deskew = argc == 10;
      sim::SimOverrides overrides;
      if (std::getenv("ICP_NO_EFFECTS")) overrides.sensor_effects = "off";
      sim::SimConfig c = sim::PresetConfig(sim::ParsePreset(argv[2]), std::stoi(argv[5]),
                                           sim::kExperimentSeed, overrides);
      ApplyEffectOverrides(&c);
      const bool features = std::getenv("ICP_FEATURES") != nullptr;
      c.world.kind = sim::ParseWorld(argv[3]);
      c.world.seed = std::stoull(argv[4]);
      ApplyWorldOverrides(&c);
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
        if (!features) return c.points;
        std::vector<Vec3> kept;
        for (const size_t i : LoamLikeFeatures(c)) kept.push_back(c.points[i]);
        return kept;
      };
      if (std::getenv("ICP_GROUND_CHECK")) {
        for (int j = 0; j < n; ++j) {
          const int k = first + j * gap;
          const io::PointCloud cl = sim.Scan(k);
          // Least squares z = a + b x + c y over the ground points in the lidar frame at mid.
          Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
          Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
          double zmax = 0.0;
          int cnt = 0;
          for (size_t i = 0; i < cl.size(); ++i) {
            const Vec3 w = sim.WorldFromLidar(sim.Seconds(cl.times_ns[i])) * cl.points[i];
            if (std::abs(w.z()) > 0.2 || cl.points[i].norm() > 30.0) continue;
            zmax = std::max(zmax, std::abs(w.z()));
            const Vec3 l = pose(k).Inverse() * w;
            const Eigen::Vector3d r(1.0, l.x(), l.y());
            A += r * r.transpose();
            rhs += r * l.z();
            ++cnt;
          }
          const Eigen::Vector3d x = A.ldlt().solve(rhs);
          const SE3 T = pose(k);
          const Vec3 up = T.rotation().transpose() * Vec3(0, 0, 1);
          std::printf(
              "sweep %d: %d ground points, max |z_world| %.4f m; lidar-frame plane slope x %.5f y "
              "%.5f; truth's up in lidar frame slope %.5f %.5f\n",
              k, cnt, zmax, x(1), x(2), -up.x() / up.z(), -up.y() / up.z());
        }
        return 0;
      }
      for (int j = 0; j < n; ++j) {
        const int a = first + j * gap, b = a + gap;
        Pair(std::string(argv[3]) + " sweeps " + std::to_string(a) + "-" + std::to_string(b),
             sweep(a), sweep(b), pose(a).Inverse() * pose(b));
      }
    } else if (mode == "replay" && argc >= 10) {
      return icp_pairs::Replay(argc, argv);
    } else if (mode == "seq" && (argc == 9 || (argc == 10 && std::string(argv[9]) == "nodeskew"))) {
      sim::SimOverrides overrides;
      if (std::getenv("ICP_NO_EFFECTS")) overrides.sensor_effects = "off";
      sim::SimConfig c = sim::PresetConfig(sim::ParsePreset(argv[2]), std::stoi(argv[5]),
                                           sim::kExperimentSeed, overrides);
      c.world.kind = sim::ParseWorld(argv[3]);
      c.world.seed = std::stoull(argv[4]);
      ApplyWorldOverrides(&c);
      const int first = std::stoi(argv[6]), n = std::stoi(argv[7]), window = std::stoi(argv[8]);
      const int stride = std::getenv("ICP_STRIDE") ? std::atoi(std::getenv("ICP_STRIDE")) : 1;
      if (stride < 1) throw std::invalid_argument("ICP_STRIDE must be a positive integer");
      c.duration_s = 0.1 * (first + n * stride + 2);
      c.integration_step_s = 1e-3;
      if (std::getenv("ICP_NO_NOISE")) c.lidar.range_noise = 0.0;  // with ICP_NO_EFFECTS: ideal
      const sim::LidarInertialSim sim(c);
      const double period = 1.0 / c.lidar.rate_hz;
      auto mid = [&](int k) { return sim.Seconds(sim.ScanStartNs(k)) + 0.5 * period; };
      std::vector<SE3> truth;
      for (int j = 0; j < n; ++j) truth.push_back(sim.WorldFromLidar(mid(first + j * stride)));
      // The constant-velocity model's error on the truth itself: δ(D) of point_odometry.h for
      // D = (T_{k−1}·Δ_{k−1})⁻¹·T_k, as the RMS over the sequence (the σ an exact registration
      // would give the adaptive threshold, min_motion aside).
      double model_sse = 0.0;
      for (int k = 2; k < n; ++k) {
        const SE3 D = (truth[k - 1] * (truth[k - 2].Inverse() * truth[k - 1])).Inverse() * truth[k];
        const double d = D.translation().norm() + 2.0 * std::min(100.0, c.lidar.max_range) *
                                                      std::sin(0.5 * D.Log().tail<3>().norm());
        model_sse += d * d;
      }
      std::printf("truth's constant-velocity model error (RMS): %.3f m\n",
                  std::sqrt(model_sse / std::max(1, n - 2)));
      if (std::getenv("ICP_TRUTH_ONLY")) return 0;
      eval::PointOdometryOptions options;
      options.deskew = argc == 9;
      options.max_range = std::min(100.0, c.lidar.max_range);
      if (const char* s = std::getenv("ICP_FIXED_SIGMA")) options.fixed_sigma = std::atof(s);
      if (const char* s = std::getenv("ICP_MIN_RANGE")) options.min_range = std::atof(s);
      if (const char* s = std::getenv("ICP_MAX_POINTS"))
        options.max_points_per_voxel = std::atoi(s);
      if (const char* s = std::getenv("ICP_CONVERGED")) options.converged = std::atof(s);
      if (const char* s = std::getenv("ICP_MAX_RANGE"))
        options.max_range = options.map_radius = std::atof(s);
      const bool true_deskew = std::getenv("ICP_TRUE_DESKEW") != nullptr;
      if (true_deskew) options.deskew = false;
      if (const char* s = std::getenv("ICP_MAP_VOXEL")) {
        options.map_voxel = std::atof(s);
        options.source_voxel = 1.5 * options.map_voxel;
      }
      // Started in motion: the true relative motion of the first two sweeps as the initial
      // constant velocity (the odometry cannot know it from one sweep).
      eval::PointOdometry odometry(truth.front(), options, truth[0].Inverse() * truth[1]);
      double cpu = 0.0;
      for (int j = 0; j < n; ++j) {
        const int k = first + j * stride;
        io::PointCloud cloud = sim.Scan(k);
        std::vector<double> times(cloud.size());
        for (size_t i = 0; i < cloud.size(); ++i)
          times[i] = sim.Seconds(cloud.times_ns[i]) - mid(k);
        if (true_deskew) {
          // Deskewed with the truth (the odometry's own deskew off): its registration alone.
          const SE3 mid_inv = sim.WorldFromLidar(mid(k)).Inverse();
          for (size_t i = 0; i < cloud.size(); ++i) {
            cloud.points[i] =
                mid_inv * (sim.WorldFromLidar(sim.Seconds(cloud.times_ns[i])) * cloud.points[i]);
          }
        }
        const std::clock_t c0 = std::clock();
        const SE3 est = odometry.Register(cloud.points, times, stride * period);
        cpu += double(std::clock() - c0) / CLOCKS_PER_SEC;
        if (std::getenv("ICP_ABS")) {
          const SE3 e = truth[j].Inverse() * est;
          const Vec3 r = e.Log().tail<3>() * 180.0 / M_PI;
          std::printf("abs %d: %+.3f %+.3f %+.3f m %+.3f %+.3f %+.3f deg\n", k, e.translation().x(),
                      e.translation().y(), e.translation().z(), r.x(), r.y(), r.z());
        }
        if (std::getenv("ICP_VERBOSE")) {
          // Relative to the previous sweep, in the truth's lidar frame.
          const std::vector<SE3>& e = odometry.poses();
          const SE3 d =
              j == 0 ? SE3()
                     : (truth[j - 1].Inverse() * truth[j]).Inverse() * (e[j - 1].Inverse() * e[j]);
          const Vec3 r = d.Log().tail<3>() * 180.0 / M_PI;
          const Vec3 step =
              j == 0 ? Vec3::Zero() : (truth[j - 1].Inverse() * truth[j]).translation();
          std::printf("sweep %d: true step %+.2f %+.2f %+.2f m; ", k, step.x(), step.y(), step.z());
          std::printf(
              "error %.3f m, sigma %.3f m; step error %+.3f %+.3f %+.3f m "
              "%+.3f %+.3f %+.3f deg\n",
              (est.translation() - truth[j].translation()).norm(), odometry.sigmas().back(),
              d.translation().x(), d.translation().y(), d.translation().z(), r.x(), r.y(), r.z());
        }
      }
      const std::vector<SE3>& est = odometry.poses();

      // Tracked: the sweeps before the first one more than 1 m off the truth (the figures below
      // are over those; a run that never leaves has tracked = n).
      int tracked = 0;
      while (tracked < n && est[tracked].translation().allFinite() &&
             (est[tracked].translation() - truth[tracked].translation()).norm() < 1.0) {
        ++tracked;
      }
      const int m = std::max(tracked, 1);
      double path = 0.0;
      for (int k = 1; k < m; ++k)
        path += (truth[k].translation() - truth[k - 1].translation()).norm();
      const double final_error = (est[m - 1].translation() - truth[m - 1].translation()).norm();
      double rel_t = 0.0, rel_r = 0.0, rel_d = 0.0;
      int windows = 0;
      for (int k = 0; k + window < m; ++k) {
        const SE3 dt = truth[k].Inverse() * truth[k + window];
        const SE3 e = dt.Inverse() * (est[k].Inverse() * est[k + window]);
        rel_t += e.translation().norm();
        rel_r += e.Log().tail<3>().norm() * 180.0 / M_PI;
        rel_d += dt.translation().norm();
        ++windows;
      }
      double sigma_sum = 0.0;
      for (int k = 1; k < m; ++k) sigma_sum += odometry.sigmas()[k];
      std::printf(
          "%s %s seed %s index %s sweeps %d-%d%s: tracked %d of %d sweeps (error < 1 m); over "
          "them: path %.1f m, error at the end %.3f m (%.2f %%); over %d windows of %d sweeps "
          "(mean %.2f m): %.3f m (%.2f %%), %.3f deg; mean sigma %.2f m; %.0f ms CPU per sweep\n",
          argv[2], argv[3], argv[4], argv[5], first, first + (n - 1) * stride,
          options.deskew ? "" : " (no deskew)", tracked, n, path, final_error,
          100.0 * final_error / std::max(path, 1e-9), windows, window, rel_d / std::max(windows, 1),
          rel_t / std::max(windows, 1), 100.0 * rel_t / std::max(rel_d, 1e-9),
          rel_r / std::max(windows, 1), sigma_sum / std::max(m - 1, 1), 1e3 * cpu / n);
      return 0;
    } else {
      std::cerr
          << "usage: icp_pairs real <graph.txt> <sweep>... | icp_pairs replay <preset> <world> "
             "<world_seed> <index> <places> <graph.txt> <sweep>... | icp_pairs sim <preset> "
             "<world> "
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
