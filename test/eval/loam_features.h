// LOAM feature selection (Zhang & Singh, RSS 2014, Sec. V-A) for the icp_pairs experiment: edge and
// planar points picked per scan line from the smoothness of each point along its line, the scheme
// the real Newer College 01 feature files are named after (their extractor's parameters are not
// stated). Not a library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::icp_pairs {

// Defaults are the LOAM reference implementation's (loam_velodyne, also A-LOAM): the paper gives
// the scheme but not these numbers, and the real files' source states none either.
struct LoamFeatureOptions {
  int half_window = 5;             // neighbours on each side for the smoothness (the set S)
  int sectors = 6;                 // equal sectors per line (the paper: four subregions)
  int sharp_per_sector = 2;        // edge points with the highest smoothness value
  int less_sharp_per_sector = 20;  // edge points kept for the map (includes the sharp ones)
  int flat_per_sector = 4;         // planar points with the lowest smoothness value
  double threshold = 0.1;          // c above: edge candidate; below: planar candidate [m²]
  double neighbour_gap2 = 0.05;    // [m²] squared step beyond which neighbours stay pickable
  double planar_voxel = 0.2;       // [m] the "less flat" planar set thinned to one per voxel
};

struct LoamFeatures {
  std::vector<size_t> edges;   // "less sharp": at most less_sharp_per_sector per sector
  std::vector<size_t> planes;  // "less flat": per line, every point not an edge, one per voxel
  std::vector<size_t> sharp;   // subset of edges
  std::vector<size_t> flat;    // at most flat_per_sector per sector
};

// `points` in firing order within each line; `ring` the line of each point (empty: one line).
// The smoothness of point i is c_i = |Σ_{j ∈ S} (p_j − p_i)|², S its half_window neighbours on each
// side along the line (the reference implementation's unnormalised square of the paper's Eq. 1).
LoamFeatures SelectLoamFeatures(const std::vector<Vec3>& points, const std::vector<uint16_t>& ring,
                                const LoamFeatureOptions& options = LoamFeatureOptions());

}  // namespace ctlio::icp_pairs
