#include "loam_features.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

namespace ctlio::icp_pairs {

LoamFeatures SelectLoamFeatures(const std::vector<Vec3>& points, const std::vector<uint16_t>& ring,
                                const LoamFeatureOptions& o) {
  if (!ring.empty() && ring.size() != points.size())
    throw std::invalid_argument("SelectLoamFeatures: ring has " + std::to_string(ring.size()) +
                                " entries for " + std::to_string(points.size()) + " points");
  if (o.half_window < 1 || o.sectors < 1 || o.planar_voxel <= 0.0)
    throw std::invalid_argument("SelectLoamFeatures: half_window, sectors, voxel must be > 0");
  std::map<int, std::vector<size_t>> lines;
  for (size_t i = 0; i < points.size(); ++i) lines[ring.empty() ? 0 : ring[i]].push_back(i);

  LoamFeatures out;
  std::vector<char> is_edge(points.size(), 0);
  const int w = o.half_window;
  for (const auto& line : lines) {
    const std::vector<size_t>& idx = line.second;
    const int n = int(idx.size());
    if (n < 2 * w + 2) continue;
    std::vector<double> c(n, 0.0);
    for (int k = w; k < n - w; ++k) {
      Vec3 d = Vec3::Zero();
      for (int j = -w; j <= w; ++j) d += points[idx[k + j]] - points[idx[k]];
      c[k] = d.squaredNorm();
    }
    // A picked point's neighbours are not picked again (the paper: features spread out), unless
    // the line jumps between them (another surface: nothing shared to suppress).
    std::vector<char> picked(n, 0);
    const auto suppress = [&](int k) {
      picked[k] = 1;
      for (int s : {-1, 1}) {
        for (int l = 1; l <= w; ++l) {
          const int a = k + s * l, b = k + s * (l - 1);
          if (a < 0 || a >= n) break;
          if ((points[idx[a]] - points[idx[b]]).squaredNorm() > o.neighbour_gap2) break;
          picked[a] = 1;
        }
      }
    };
    for (int s = 0; s < o.sectors; ++s) {
      // Sector bounds over the points that have a full window (k in [w, n - w)).
      const int begin = w + (n - 2 * w) * s / o.sectors;
      const int end = w + (n - 2 * w) * (s + 1) / o.sectors;
      std::vector<int> order;
      for (int k = begin; k < end; ++k) order.push_back(k);
      std::sort(order.begin(), order.end(), [&](int a, int b) { return c[a] < c[b]; });
      int edges = 0;
      for (auto it = order.rbegin(); it != order.rend() && edges < o.less_sharp_per_sector; ++it) {
        const int k = *it;
        if (picked[k] || c[k] <= o.threshold) continue;
        if (edges < o.sharp_per_sector) out.sharp.push_back(idx[k]);
        out.edges.push_back(idx[k]);
        is_edge[idx[k]] = 1;
        ++edges;
        suppress(k);
      }
      int flats = 0;
      for (auto it = order.begin(); it != order.end() && flats < o.flat_per_sector; ++it) {
        const int k = *it;
        if (picked[k] || c[k] >= o.threshold) continue;
        out.flat.push_back(idx[k]);
        ++flats;
        suppress(k);
      }
    }
    // "Less flat": every point of the line's sectors that is not an edge, thinned per line to
    // the first point of each voxel (the reference implementation keeps the voxel's centroid; an
    // index keeps a measured point).
    std::map<std::tuple<int64_t, int64_t, int64_t>, size_t> voxels;
    for (int k = w; k < n - w; ++k) {
      if (is_edge[idx[k]]) continue;
      const Vec3& p = points[idx[k]];
      voxels.emplace(std::make_tuple(int64_t(std::floor(p.x() / o.planar_voxel)),
                                     int64_t(std::floor(p.y() / o.planar_voxel)),
                                     int64_t(std::floor(p.z() / o.planar_voxel))),
                     idx[k]);
    }
    for (const auto& [key, i] : voxels) out.planes.push_back(i);
  }
  std::sort(out.planes.begin(), out.planes.end());
  std::sort(out.edges.begin(), out.edges.end());
  return out;
}

}  // namespace ctlio::icp_pairs
