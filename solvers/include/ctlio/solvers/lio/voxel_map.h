// Voxel hash map of the lidar front end (SPEC §4, as in CT-ICP): map points are stored in cubic
// voxels of `voxel_size` (1.0 m) keyed by their integer grid coordinates; each voxel keeps at
// most `max_points_per_voxel` (20) points at least `min_point_distance` (0.1 m) apart, so the
// density is bounded wherever the robot lingers; voxels farther than `max_distance` (400 m)
// from the robot are removed. Neighbours of a query are searched in its voxel and the 26 around
// it (±1 voxel): every map point within one voxel size of the query is found exactly.
//
// Storage is flat: an open-addressing table (linear probing, load ≤ 1/2) maps a voxel key to a
// voxel index, and voxel i is one record in a pool of chunks (256 voxels each: the pool grows
// without reallocating, so without copies and without a transient second pool in the peak
// memory): its key and point count, then a fixed block of max_points_per_voxel points, the record
// aligned to a cache line. A lookup is a hash, a few adjacent slots and the record, whose first
// line holds the key to compare, the count and the first points: two cache misses for a voxel
// not in cache, where separate key, count and point arrays were four.
//
// Per-voxel planes (Options::fit_planes, as in iG-LIO and VoxelMap): each voxel also keeps the
// sums Σd and Σd·dᵀ of its points (d relative to the voxel's corner, so the sums stay well
// conditioned anywhere in the map) and the PCA plane of those moments. An insertion updates the
// sums and marks the voxel; the planes of the marked voxels are refitted once at the end of the
// insertion (a full voxel, the common case in a mapped area, never changes), so queries are
// const and a voxel's plane is a hash lookup.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include "ctlio/manifolds/types.h"
#include "ctlio/solvers/lio/plane_fit.h"

namespace ctlio::lio {

struct VoxelKey {
  int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

// ⌊a⌋ for |a| < 2³¹: truncation toward zero, one down for a negative non-integer — std::floor's
// value without its rounding-mode sequence (no SSE4.1 roundsd in a generic x86-64 build).
inline int32_t FloorToInt(double a) {
  const int32_t t = static_cast<int32_t>(a);
  return t - (a < static_cast<double>(t) ? 1 : 0);
}

inline VoxelKey VoxelKeyOf(const Vec3& p, double inverse_voxel_size) {
  return {FloorToInt(p.x() * inverse_voxel_size), FloorToInt(p.y() * inverse_voxel_size),
          FloorToInt(p.z() * inverse_voxel_size)};
}

// splitmix64's finaliser: spreads packed voxel coordinates over the slots of the
// open-addressing tables (map and subsampling).
inline uint64_t MixVoxelHash(uint64_t k) {
  k ^= k >> 30;
  k *= 0xbf58476d1ce4e5b9ull;
  k ^= k >> 27;
  k *= 0x94d049bb133111ebull;
  k ^= k >> 31;
  return k;
}

// The points of one voxel: a contiguous block of the map's pool, valid until the next Insert,
// RemoveFar or Clear.
struct VoxelPoints {
  const Vec3* data = nullptr;
  size_t count = 0;
  size_t size() const { return count; }
  const Vec3* begin() const { return data; }
  const Vec3* end() const { return data + count; }
  const Vec3& operator[](size_t i) const { return data[i]; }
};

// The plane of one voxel's points; `points` is how many it was fitted to (0: no plane, i.e.
// fewer than three points or a degenerate spread).
struct VoxelPlane {
  PlaneFit fit;
  int32_t points = 0;
};

class VoxelMap {
 public:
  struct Options {
    double voxel_size = 1.0;
    int max_points_per_voxel = 20;
    double min_point_distance = 0.1;
    double max_distance = 400.0;
    bool fit_planes = false;  // keep each voxel's moments and plane (PlaneOf)
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

  // The plane of the voxel containing p, or nullptr when p's voxel is empty or the map keeps no
  // planes (Options::fit_planes false).
  const VoxelPlane* PlaneOf(const Vec3& p) const;

  size_t num_points() const { return num_points_; }
  size_t num_voxels() const { return num_voxels_; }
  const Options& options() const { return options_; }
  void Clear();

  // Calls f(key, VoxelPoints) for every voxel (unordered).
  template <typename F>
  void ForEachVoxel(F&& f) const {
    for (size_t i = 0; i < num_voxels_; ++i) {
      const int32_t voxel = static_cast<int32_t>(i);
      f(HeaderOf(voxel)->key, PointsOf(voxel));
    }
  }

 private:
  static constexpr int32_t kNoVoxel = -1;
  static constexpr int kChunkBits = 8;  // 256 voxels per pool chunk
  // A voxel's record: this header, then max_points_per_voxel points (kHeaderBytes on).
  struct VoxelHeader {
    VoxelKey key;
    int32_t count = 0;
  };
  static constexpr size_t kHeaderBytes = 16;
  static_assert(sizeof(VoxelHeader) <= kHeaderBytes && kHeaderBytes % alignof(Vec3) == 0);
  struct alignas(64) CacheLine {
    unsigned char bytes[64];
  };
  CacheLine* RecordOf(int32_t voxel) const {
    constexpr int32_t kChunkMask = (1 << kChunkBits) - 1;
    return pool_[voxel >> kChunkBits].get() +
           static_cast<size_t>(voxel & kChunkMask) * record_lines_;
  }
  VoxelHeader* HeaderOf(int32_t voxel) const {
    return std::launder(reinterpret_cast<VoxelHeader*>(RecordOf(voxel)->bytes));
  }
  Vec3* BlockOf(int32_t voxel) const {
    return std::launder(reinterpret_cast<Vec3*>(RecordOf(voxel)->bytes + kHeaderBytes));
  }
  VoxelPoints PointsOf(int32_t voxel) const {
    return {BlockOf(voxel), static_cast<size_t>(HeaderOf(voxel)->count)};
  }
  // Starts voxel's record (key, no points) in the pool; voxel is the next index.
  void ConstructRecord(int32_t voxel, const VoxelKey& key);
  // The voxel index of key, or kNoVoxel.
  int32_t Find(const VoxelKey& key) const;
  // The voxel index of key, creating an empty voxel if there is none.
  int32_t FindOrAdd(const VoxelKey& key);
  // Rebuilds the slot table for the current voxels with min_slots slots or more (a power of two).
  void Rehash(size_t min_slots);
  // Insert's body once the voxel of p is known.
  bool InsertInto(int32_t voxel, const Vec3& p);
  // Refits the planes of the voxels whose points changed since the last call.
  void RefitChangedPlanes();
  // Whether p lies closer than min_point_distance to one of the n points at `points`.
  bool HasPointCloserThanMin(const Vec3* points, int32_t n, const Vec3& p) const;

  // Insert's direct-mapped cache of voxel lookups (a few thousand entries, L1/L2-resident):
  // the same beam of the next firings mostly falls in the voxel it fell in before, a firing's
  // worth of points back, where the previous-point shortcut does not reach. Filled and read
  // within one Insert call only (voxel indices stay valid until RemoveFar or Clear).
  static constexpr int kRecentBits = 10;
  struct RecentVoxel {
    VoxelKey key;
    int32_t voxel = kNoVoxel;
  };
  static size_t RecentSlot(const VoxelKey& k) {
    const uint32_t h = static_cast<uint32_t>(k.x) * 0x9e3779b1u ^
                       static_cast<uint32_t>(k.y) * 0x85ebca77u ^
                       static_cast<uint32_t>(k.z) * 0xc2b2ae3du;
    return h >> (32 - kRecentBits);
  }
  std::vector<RecentVoxel> recent_;

  // Σd and the upper triangle of Σd·dᵀ (xx, xy, xz, yy, yz, zz) of a voxel's points, d = p − the
  // voxel's corner.
  struct Moments {
    Vec3 sum = Vec3::Zero();
    double sq[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  };

  Options options_;
  double inverse_voxel_size_;
  double min_distance2_;
  size_t stride_;        // max_points_per_voxel
  size_t record_lines_;  // cache lines per record: header + stride_ points
  // Voxel index per slot (kNoVoxel: empty), power-of-two size or empty; the key is compared in
  // the record. 4 bytes a slot rather than the key's 12 more: the table of a mapped room stays
  // in L2, where a lookup was an L3 miss.
  std::vector<int32_t> slots_;
  size_t num_voxels_ = 0;
  std::vector<std::unique_ptr<CacheLine[]>> pool_;  // chunks of 2^kChunkBits records
  // With fit_planes only, per voxel:
  std::vector<Moments> moments_;
  std::vector<VoxelPlane> planes_;
  std::vector<uint8_t> changed_;         // points added since the last refit
  std::vector<int32_t> changed_voxels_;  // the voxels with changed_ set
  size_t num_points_ = 0;
};

}  // namespace ctlio::lio
