// icp_pairs replay: the real Newer College keyframes' relative poses replayed in a simulated
// world (usage and output in icp_pairs.cc's header; docs/experiments/worlds-geometry.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/presets.h"
#include "icp_pairs.h"
#include "loam_features.h"

namespace ctlio::icp_pairs {
namespace {

// What a registration has to hold on to: points, occupied 0.5 m voxels (the ICP's source
// sampling), median range, and the share of points more than 1 m below the sensor (the ground,
// which constrains no horizontal motion).
std::string Describe(const std::vector<Vec3>& points) {
  std::vector<double> range;
  std::map<std::tuple<int, int, int>, int> voxels;
  int low = 0;
  // Above the ground: how many of 12 azimuth sectors of 30° hold at least 20 such points within
  // 30 m, and the median horizontal range of those points (what fixes the horizontal motion).
  int sector_points[12] = {0};
  std::vector<double> upright_range;
  for (const Vec3& p : points) {
    range.push_back(p.norm());
    ++voxels[{int(std::floor(p.x() / 0.5)), int(std::floor(p.y() / 0.5)),
              int(std::floor(p.z() / 0.5))}];
    low += p.z() < -1.0;
    const double r = std::hypot(p.x(), p.y());
    if (p.z() >= -1.0) {
      upright_range.push_back(r);
      if (r < 30.0) {
        const int k = int(std::floor((std::atan2(p.y(), p.x()) + M_PI) / (M_PI / 6.0)));
        ++sector_points[std::clamp(k, 0, 11)];
      }
    }
  }
  if (range.empty()) return "no points";
  std::nth_element(range.begin(), range.begin() + range.size() / 2, range.end());
  int sectors = 0;
  for (const int n : sector_points) sectors += n >= 20;
  double upright_median = 0.0;
  if (!upright_range.empty()) {
    std::nth_element(upright_range.begin(), upright_range.begin() + upright_range.size() / 2,
                     upright_range.end());
    upright_median = upright_range[upright_range.size() / 2];
  }
  char text[240];
  std::snprintf(text, sizeof(text),
                "%zu points, %zu voxels of 0.5 m, median range %.1f m, %.0f %% "
                "below z -1 m; above it: %d of 12 sectors within 30 m, median range %.1f m",
                points.size(), voxels.size(), range[range.size() / 2],
                100.0 * low / double(points.size()), sectors, upright_median);
  return text;
}

// P(X ≥ k) for X ~ Binomial(n, 1/2): the one-sided sign test.
double SignTestP(int k, int n) {
  double p = 0.0;
  for (int x = k; x <= n; ++x)
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(x + 1.0) - std::lgamma(n - x + 1.0) -
                  n * std::log(2.0));
  return p;
}

// Exact one-sided Wilcoxon signed-rank test of "the differences are larger than 0": the share of
// the 2^n sign assignments whose positive rank sum reaches the observed one (n ≤ 20; ties in |d|
// get their mean rank).
double SignedRankP(const std::vector<double>& d) {
  const int n = int(d.size());
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return std::abs(d[a]) < std::abs(d[b]); });
  std::vector<double> rank(n);
  for (int i = 0; i < n;) {
    int j = i;
    while (j + 1 < n && std::abs(d[order[j + 1]]) == std::abs(d[order[i]])) ++j;
    for (int k = i; k <= j; ++k) rank[order[k]] = 0.5 * (i + j) + 1.0;
    i = j + 1;
  }
  double observed = 0.0;
  for (int i = 0; i < n; ++i) observed += d[i] > 0 ? rank[i] : 0.0;
  int reach = 0;
  for (uint32_t m = 0; m < (1u << n); ++m) {
    double w = 0.0;
    for (int i = 0; i < n; ++i) w += (m >> i) & 1u ? rank[i] : 0.0;
    reach += w >= observed - 1e-9;
  }
  return double(reach) / double(1u << n);
}

}  // namespace

int Replay(int argc, char** argv) {
  const std::vector<SE3> poses = ReadGraph(argv[7]);
  const int sweeps = std::min(argc - 8, int(poses.size()));
  if (sweeps < 2) throw std::invalid_argument("replay: at least two keyframes with poses");
  const int places = std::stoi(argv[6]);
  if (places < 1) throw std::invalid_argument("replay: places must be a positive integer");
  const bool raw = std::getenv("ICP_RAW") != nullptr;
  std::vector<std::pair<int, int>> ij;
  for (int i = 0; i + 1 < sweeps; ++i)
    for (int j = i + 1; j < sweeps; ++j) ij.push_back({i, j});
  std::vector<double> dist, real;  // per pair: spacing [m], real error [% of the spacing]
  for (int k = 0; k < sweeps; ++k)
    std::printf("real keyframe %d: %s\n", k, Describe(ReadSweep(argv[8 + k])).c_str());
  for (const auto& [i, j] : ij) {
    const SE3 rel = poses[i].Inverse() * poses[j];
    dist.push_back(rel.translation().norm());
    real.push_back(100.0 *
                   Pair("real " + std::to_string(i) + "-" + std::to_string(j),
                        ReadSweep(argv[8 + i]), ReadSweep(argv[8 + j]), rel) /
                   dist.back());
  }

  sim::SimOverrides overrides;
  if (std::getenv("ICP_NO_EFFECTS")) overrides.sensor_effects = "off";
  sim::SimConfig c = sim::PresetConfig(sim::ParsePreset(argv[2]), std::stoi(argv[5]),
                                       sim::kExperimentSeed, overrides);
  ApplyEffectOverrides(&c);
  c.world.kind = sim::ParseWorld(argv[3]);
  c.world.seed = std::stoull(argv[4]);
  ApplyWorldOverrides(&c);
  // ICP_PLACE_GAP=s: the places s seconds of the walk apart (4 s unless given).
  const double gap = std::getenv("ICP_PLACE_GAP") ? std::atof(std::getenv("ICP_PLACE_GAP")) : 4.0;
  if (!(gap > 0.0)) throw std::invalid_argument("ICP_PLACE_GAP must be positive");
  c.duration_s = 2.0 + gap * places + 4.0;
  c.integration_step_s = 1e-3;
  const sim::LidarInertialSim path(c);
  // The real keyframes' overall direction of travel in the first keyframe's frame.
  const Vec3 travel = (poses[0].Inverse() * poses[sweeps - 1]).translation();
  const double real_heading = std::atan2(travel.y(), travel.x());
  std::vector<std::vector<double>> simulated(ij.size());  // per pair, per place [%]
  std::vector<double> ground(places, 0.0);  // per place: mean share of kept points below -1 m
  for (int p = 0; p < places; ++p) {
    const double t = 2.0 + gap * p;
    const Vec3 at = path.WorldFromLidar(t).translation();
    const Vec3 ahead = path.WorldFromLidar(t + 3.0).translation() - at;
    const double turn = std::atan2(ahead.y(), ahead.x()) - real_heading;
    const SE3 start(Eigen::AngleAxisd(turn, Vec3::UnitZ()).toRotationMatrix(), at);
    std::vector<std::vector<Vec3>> kept(sweeps);
    for (int k = 0; k < sweeps; ++k) {
      // Standing still at the replayed keyframe: its own noise, the preset unit's errors.
      sim::SimConfig still = c;
      still.motion = sim::MotionProfile();
      still.lidar.unit_seed = c.lidar.unit_seed != 0 ? c.lidar.unit_seed : c.seed;
      still.seed = c.seed + 1000u * uint64_t(p + 1) + uint64_t(k);
      still.imu.outages.clear();
      still.imu.outage_rate = 0.0;
      still.duration_s = 0.35;
      const SE3 lidar = start * (poses[0].Inverse() * poses[k]);
      still.world_from_imu0 = lidar * c.imu_from_lidar.Inverse();
      const sim::LidarInertialSim s(still);
      const io::PointCloud cloud = s.Scan(1);
      const double clearance = s.CastRay(lidar.translation(), -Vec3::UnitZ());
      size_t edges = 0;
      if (!raw && std::getenv("ICP_PROPORTIONAL_FEATURES") == nullptr)
        edges =
            SelectLoamFeatures(cloud.points, cloud.ring, LoamOptionsFromEnvironment()).edges.size();
      if (raw) {
        kept[k] = cloud.points;
      } else {
        for (const size_t i : LoamLikeFeatures(cloud)) kept[k].push_back(cloud.points[i]);
      }
      for (const Vec3& q : kept[k]) ground[p] += q.z() < -1.0 ? 1.0 / kept[k].size() / sweeps : 0.0;
      std::printf(
          "place %d (t %.0f s, at %.0f %.0f m) keyframe %d: %zu points in the sweep, %.2f m "
          "above "
          "ground; "
          "kept %s (%zu edges)\n",
          p, t, at.x(), at.y(), k, cloud.size(), clearance, Describe(kept[k]).c_str(), edges);
    }
    for (size_t q = 0; q < ij.size(); ++q) {
      const auto [i, j] = ij[q];
      const double e =
          Pair("place " + std::to_string(p) + " " + std::to_string(i) + "-" + std::to_string(j),
               kept[i], kept[j], poses[i].Inverse() * poses[j]);
      simulated[q].push_back(100.0 * e / dist[q]);
    }
  }

  // Pair by pair: the same relative motion, real against simulated.
  std::printf("\npair  spacing  real %%  sim mean / median [min-max] %%  places sim > real\n");
  std::vector<double> diff;
  int above = 0, cells_above = 0;
  for (size_t q = 0; q < ij.size(); ++q) {
    std::vector<double> v = simulated[q];
    std::sort(v.begin(), v.end());
    double mean = 0.0;
    for (const double x : v) mean += x / double(v.size());
    const size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    int over = 0;
    for (const double x : v) over += x > real[q];
    cells_above += over;
    std::printf("%d-%d  %5.2f m  %5.2f   %5.2f / %5.2f [%5.2f-%5.2f]   %d of %zu\n", ij[q].first,
                ij[q].second, dist[q], real[q], mean, median, v.front(), v.back(), over, n);
    diff.push_back(median - real[q]);
    above += median > real[q];
  }
  double real_e = 0.0, sum_d = 0.0;
  for (size_t q = 0; q < ij.size(); ++q) {
    real_e += real[q] * dist[q];
    sum_d += dist[q];
  }
  std::printf("real: Σerror/Σspacing %.2f %%\n", real_e / sum_d);
  int places_above = 0;
  for (int p = 0; p < places; ++p) {
    double e = 0.0;
    for (size_t q = 0; q < ij.size(); ++q) e += simulated[q][p] * dist[q];
    places_above += e > real_e;
    std::printf("place %d: Σerror/Σspacing %.2f %%, %.0f %% of the kept points below z -1 m\n", p,
                e / sum_d, 100.0 * ground[p]);
  }
  const int cells = int(ij.size()) * places;
  std::printf(
      "sim > real: %d of %zu pairs by the median over places (sign test p = %.3f, signed-rank "
      "p = %.3f); %d of %d places overall (p = %.3f); %d of %d place-pairs\n",
      above, ij.size(), SignTestP(above, int(ij.size())), SignedRankP(diff), places_above, places,
      SignTestP(places_above, places), cells_above, cells);
  return 0;
}

}  // namespace ctlio::icp_pairs
