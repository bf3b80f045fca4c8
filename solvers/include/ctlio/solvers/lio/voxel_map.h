// Voxel hash map of the lidar front end (SPEC §4, as in CT-ICP): map points are stored in cubic
// voxels of `voxel_size` (1.0 m) keyed by their integer grid coordinates; each voxel keeps at
// most `max_points_per_voxel` (20) points at least `min_point_distance` (0.1 m) apart, so the
// density is bounded wherever the robot lingers; voxels farther than `max_distance` (400 m)
// from the robot are removed. Neighbours of a query are searched in its voxel and the 26 around
// it (±1 voxel): every map point within one voxel size of the query is found exactly.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

struct VoxelKey {
  int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

inline VoxelKey VoxelKeyOf(const Vec3& p, double inverse_voxel_size) {
  return {static_cast<int32_t>(std::floor(p.x() * inverse_voxel_size)),
          static_cast<int32_t>(std::floor(p.y() * inverse_voxel_size)),
          static_cast<int32_t>(std::floor(p.z() * inverse_voxel_size))};
}

struct VoxelKeyHash {
  // The spatial hash of Teschner et al. (2003), used by CT-ICP and KISS-ICP.
  size_t operator()(const VoxelKey& k) const {
    return static_cast<size_t>((static_cast<uint64_t>(static_cast<uint32_t>(k.x)) * 73856093u) ^
                               (static_cast<uint64_t>(static_cast<uint32_t>(k.y)) * 19349669u) ^
                               (static_cast<uint64_t>(static_cast<uint32_t>(k.z)) * 83492791u));
  }
};

class VoxelMap {
 public:
  struct Options {
    double voxel_size = 1.0;
    int max_points_per_voxel = 20;
    double min_point_distance = 0.1;
    double max_distance = 400.0;
  };

  struct Neighbour {
    Vec3 point;
    double squared_distance;
  };

  explicit VoxelMap(const Options& options);

  // Adds a map-frame point unless its voxel is full or it lies closer than min_point_distance to
  // a point already there. Returns whether it was kept.
  bool Insert(const Vec3& p);
  // Returns the number of points kept.
  size_t Insert(const std::vector<Vec3>& points);

  // Removes every voxel whose centre is farther than max_distance from `location`; returns the
  // number of voxels removed.
  size_t RemoveFar(const Vec3& location);

  // The (at most k) points nearest to q among the voxels within ±1 of q's voxel and within
  // max_distance of q, nearest first, written into *out (its capacity is reused, so a caller
  // that keeps the vector does not allocate). Returns their number.
  int KNearest(const Vec3& q, int k, std::vector<Neighbour>* out,
               double max_distance = std::numeric_limits<double>::infinity()) const;

  size_t num_points() const { return num_points_; }
  size_t num_voxels() const { return voxels_.size(); }
  const Options& options() const { return options_; }
  void Clear();

  // Calls f(key, points) for every voxel (unordered).
  template <typename F>
  void ForEachVoxel(F&& f) const {
    for (const auto& [key, voxel] : voxels_) f(key, voxel.points);
  }

 private:
  struct Voxel {
    std::vector<Vec3> points;
  };
  // Insert's body once the voxel of p is known.
  bool InsertInto(Voxel* voxel, const Vec3& p);

  Options options_;
  double inverse_voxel_size_;
  double min_distance2_;
  std::unordered_map<VoxelKey, Voxel, VoxelKeyHash> voxels_;
  size_t num_points_ = 0;
};

}  // namespace ctlio::lio
