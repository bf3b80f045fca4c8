// The registered map of a run (ctlio_odometry --save_map): every scan's deskewed map-frame points
// (LioOdometry::newest_map_points, the ones the odometry inserted into its own voxel map) merged
// into a voxel grid with one point per occupied voxel.
//
// One point per voxel is the running centroid of the points that fell into it, not the first:
// on a surface the centroid of n returns has the range noise over √n, so walls and the ground
// come out as thin layers, and the result does not depend on which scan saw the voxel first.
// (A drifting estimate blurs both the same way: its points land in neighbouring voxels.) The
// centroid is kept as float offsets from the voxel centre, exact to micrometres at any distance
// from the origin within the ±2^20-voxel key range (±210 km at 0.2 m; points beyond are dropped
// and counted).
//
// Memory: an open-addressing hash table of 24-byte slots (8-byte key, 16-byte centroid + count)
// at a load of at most 0.7, a power of two of slots, so at most 24 B / 0.35 ≈ 69 B per stored
// point, and while it doubles the old table lives beside the new one (peak_bytes() counts both).
// It grows with the occupied voxels, i.e. with the volume of surface seen, not with the run's
// length; with max_points > 0 it stops there (new voxels are dropped, counted in dropped_points;
// the occupied ones keep averaging), so a run of hours has a hard bound of
// 24 B × next_pow2(max_points / 0.7) × 1.5.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::lioapp {

class MapAccumulator {
 public:
  // Throws std::invalid_argument unless voxel_size is finite and > 0. max_points 0: no cap.
  explicit MapAccumulator(double voxel_size, size_t max_points = 0);

  // Merges T·p for every p of `points` (map frame → output frame).
  void Add(const std::vector<Vec3>& points, const SE3& T = SE3());
  // Empties the map (the counts too); the table keeps its size, peak_bytes() its peak.
  void Clear();

  // One point per occupied voxel (the centroid of its points), in table order.
  std::vector<Vec3> Points() const;
  size_t size() const { return size_; }
  double voxel_size() const { return voxel_size_; }
  size_t max_points() const { return max_points_; }
  // Points added in total, and those left out: in a new voxel once max_points were stored, or
  // not finite / beyond the key range.
  size_t added_points() const { return added_; }
  size_t dropped_points() const { return dropped_cap_; }
  size_t out_of_range_points() const { return dropped_range_; }
  // Bytes of the table now, and the most it ever held (the doubling's old + new tables).
  size_t bytes() const;
  size_t peak_bytes() const { return peak_bytes_; }

 private:
  struct Cell {
    float dx = 0, dy = 0, dz = 0;  // centroid − voxel centre
    uint32_t n = 0;
  };
  static constexpr uint64_t kEmpty = ~uint64_t{0};
  static constexpr int kBits = 21;  // per axis, offset by 2^20 (never all ones: kEmpty is free)

  // The slot of `key`: its own or the empty one where it goes.
  size_t Find(uint64_t key) const;
  void Grow();

  double voxel_size_;
  double inv_voxel_size_;
  size_t max_points_;
  std::vector<uint64_t> keys_;
  std::vector<Cell> cells_;
  size_t size_ = 0;
  size_t added_ = 0, dropped_cap_ = 0, dropped_range_ = 0;
  size_t peak_bytes_ = 0;
};

}  // namespace ctlio::lioapp
