#include "ctlio/solvers/lio/frontend.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "ctlio/solvers/parallel_for.h"

namespace ctlio::lio {

std::vector<TimedPoint> RangeGate(const std::vector<TimedPoint>& points, double min_range,
                                  double max_range) {
  std::vector<TimedPoint> out;
  out.reserve(points.size());
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  for (const TimedPoint& p : points) {
    const double r2 = p.point.squaredNorm();
    if (std::isfinite(r2) && std::isfinite(p.time) && r2 >= min2 && r2 <= max2) out.push_back(p);
  }
  return out;
}

namespace {

// 21 bits per axis around an offset of 2²⁰ voxels: ±1,048,576 voxels (±210 km at 0.2 m).
constexpr int64_t kKeyOffset = int64_t{1} << 20;
constexpr int64_t kKeyRange = int64_t{1} << 21;
constexpr uint64_t kEmpty = ~uint64_t{0};

// ⌊a⌋ + kKeyOffset for kKeyOffset ≤ a < kKeyOffset (checked by the caller): truncation toward
// zero, one down for a negative non-integer — exactly std::floor's value, without its rounding
// mode dance on targets without SSE4.1's roundsd.
inline uint64_t FloorPlusOffset(double a) {
  const int64_t t = static_cast<int64_t>(a);
  return static_cast<uint64_t>(t - (a < static_cast<double>(t) ? 1 : 0) + kKeyOffset);
}

// The packed key of a = p / voxel size, for a point known to satisfy |a| < 2²⁰ on every axis.
inline uint64_t PackedKeyInRange(double ax, double ay, double az) {
  static_assert(3 * 21 < 64, "packed key must not collide with kEmpty");
#if defined(__SSE2__)
  // ⌊ax⌋ and ⌊ay⌋ at once (x86-64 always has SSE2): the same truncation and one-down correction
  // as FloorPlusOffset, in two 32-bit lanes (|a| < 2²⁰ fits), ~10 instructions fewer per key.
  const __m128d a = _mm_set_pd(ay, ax);
  const __m128i t = _mm_cvttpd_epi32(a);  // lanes 0, 1: trunc(ax), trunc(ay)
  const __m128i below = _mm_castpd_si128(_mm_cmplt_pd(a, _mm_cvtepi32_pd(t)));  // 64-bit masks
  const __m128i floor_xy = _mm_add_epi32(t, _mm_shuffle_epi32(below, _MM_SHUFFLE(3, 1, 2, 0)));
  const int64_t xy = _mm_cvtsi128_si64(floor_xy);
  const uint64_t fx =
      static_cast<uint64_t>(static_cast<int64_t>(static_cast<int32_t>(xy)) + kKeyOffset);
  const uint64_t fy = static_cast<uint64_t>((xy >> 32) + kKeyOffset);
  return (fx * static_cast<uint64_t>(kKeyRange) + fy) * static_cast<uint64_t>(kKeyRange) +
         FloorPlusOffset(az);
#else
  return (FloorPlusOffset(ax) * static_cast<uint64_t>(kKeyRange) + FloorPlusOffset(ay)) *
             static_cast<uint64_t>(kKeyRange) +
         FloorPlusOffset(az);
#endif
}

inline bool PackedKey(const Vec3& p, double inverse_size, uint64_t* key) {
  const double ax = p.x() * inverse_size, ay = p.y() * inverse_size, az = p.z() * inverse_size;
  // ⌊a⌋ ∈ [−2²⁰, 2²⁰ − 1] ⇔ a ∈ [−2²⁰, 2²⁰); false for NaN as well.
  constexpr double lo = -static_cast<double>(kKeyOffset), hi = static_cast<double>(kKeyOffset);
  if (!(ax >= lo && ax < hi && ay >= lo && ay < hi && az >= lo && az < hi)) return false;
  *key = PackedKeyInRange(ax, ay, az);
  return true;
}

// Whether every point that passes the range gate |p|² ≤ max² has |p / voxel size| < 2²⁰ on every
// axis, so that PackedKey's bounds check cannot fail after the gate: |x| ≤ |p| ≤ max_range
// (up to rounding of |p|², hence the factor-2 margin), and a NaN or infinite point fails the gate.
inline bool GateBoundsKey(double max_range, double inverse_size) {
  return max_range * inverse_size < 0.5 * static_cast<double>(kKeyOffset);
}

// Set of packed voxel keys (open addressing, linear probing, load ≤ 1/2) for "first point of its
// voxel" subsampling. It starts small and doubles as voxels appear: a sweep has a few ten
// thousand occupied voxels but up to 230 000 points, and sizing the table for the points (4 MB,
// cleared every sweep) made most probes cache misses. Which keys are present — hence the kept
// points and their order — does not depend on the table size.
class PackedKeySet {
 public:
  // Empties the set. The table keeps the size it grew to (sweeps of one sensor occupy similar
  // numbers of voxels, so later calls rarely rehash) and both buffers keep their capacity.
  void Clear() {
    if (table_.empty()) {
      table_.assign(kInitialCapacity, kEmpty);
      mask_ = kInitialCapacity - 1;
    } else if (8 * used_.size() < table_.size()) {
      // Reset only the slots in use: a sweep's few ten thousand voxels, not the whole table
      // (the memset of which was ~3% of AddScan's instructions).
      for (const uint64_t slot : used_) table_[slot] = kEmpty;
    } else {
      std::fill(table_.begin(), table_.end(), kEmpty);
    }
    used_.clear();
    size_ = 0;
    last_ = kEmpty;
    recent_.fill(kEmpty);
  }
  bool Contains(uint64_t key) const {
    for (uint64_t slot = MixVoxelHash(key) & mask_;; slot = (slot + 1) & mask_) {
      if (table_[slot] == key) return true;
      if (table_[slot] == kEmpty) return false;
    }
  }
  // Inserts key; returns whether it was new.
  bool Insert(uint64_t key) {
    // Consecutive returns of a firing mostly fall in the voxel of the previous one, which is in
    // the set by then: answer without hashing or probing.
    if (key == last_) return false;
    last_ = key;
    // The same beam of the next firings mostly hits the voxel it hit before (a 0.5 m voxel spans
    // ~10 firings at 10 m), ~128 returns back: a small direct-mapped cache of keys known to be
    // in the table answers those without the hash and the probe. It only ever holds keys of the
    // table, so a hit is exact; a miss falls through to the table, which stays the truth.
    uint64_t& recent = recent_[(key * 0x9e3779b97f4a7c15ull) >> (64 - kRecentBits)];
    if (recent == key) return false;
    recent = key;  // in the table once this call returns
    if (2 * (size_ + 1) > table_.size()) Grow();
    for (uint64_t slot = MixVoxelHash(key) & mask_;; slot = (slot + 1) & mask_) {
      if (table_[slot] == key) return false;
      if (table_[slot] == kEmpty) {
        table_[slot] = key;
        used_.push_back(slot);
        ++size_;
        return true;
      }
    }
  }

 private:
  static constexpr size_t kInitialCapacity = 4096;
  static constexpr int kRecentBits = 10;  // 1024 keys, 8 KB: stays in L1
  void Grow() {
    spare_.assign(2 * table_.size(), kEmpty);
    const uint64_t mask = spare_.size() - 1;
    used_.clear();
    for (const uint64_t key : table_) {
      if (key == kEmpty) continue;
      uint64_t slot = MixVoxelHash(key) & mask;
      while (spare_[slot] != kEmpty) slot = (slot + 1) & mask;
      spare_[slot] = key;
      used_.push_back(slot);
    }
    table_.swap(spare_);
    mask_ = mask;
  }
  std::vector<uint64_t> table_, spare_;
  std::vector<uint64_t> used_;  // the slots holding a key
  uint64_t mask_ = 0;
  size_t size_ = 0;
  uint64_t last_ = kEmpty;                                 // the key of the previous Insert
  std::array<uint64_t, size_t{1} << kRecentBits> recent_;  // keys of the table (or kEmpty)
};

}  // namespace

std::vector<TimedPoint> VoxelGridSubsample(const std::vector<TimedPoint>& points,
                                           double voxel_size) {
  if (!(voxel_size > 0.0)) throw std::invalid_argument("VoxelGridSubsample: voxel_size <= 0");
  std::vector<TimedPoint> out;
  if (points.empty()) return out;
  // Reused across calls (per thread): fresh tables per sweep cost allocations and page faults.
  thread_local PackedKeySet seen;
  seen.Clear();
  const double inverse_size = 1.0 / voxel_size;
  for (const TimedPoint& p : points) {
    uint64_t key;
    if (!PackedKey(p.point, inverse_size, &key)) continue;  // non-finite or absurdly far
    if (seen.Insert(key)) out.push_back(p);
  }
  return out;
}

namespace {

// The indices in [begin, end) of the points in the range band that are the first of their voxel
// within [begin, end), in order; `seen` ends up holding those points' voxels.
// With kGateBoundsKey (GateBoundsKey true) the key's bounds check is skipped: the gate implies it.
template <bool kGateBoundsKey>
void FirstOfVoxelInBand(const std::vector<Vec3>& points, size_t begin, size_t end,
                        double inverse_size, double min2, double max2, PackedKeySet* seen,
                        std::vector<size_t>* out) {
  seen->Clear();
  const Vec3* p = points.data();
  for (size_t i = begin; i < end; ++i) {
    const double r2 = p[i].squaredNorm();
    if (!(r2 >= min2 && r2 <= max2)) continue;  // also drops non-finite points
    uint64_t key;
    if constexpr (kGateBoundsKey) {
      key = PackedKeyInRange(p[i].x() * inverse_size, p[i].y() * inverse_size,
                             p[i].z() * inverse_size);
    } else if (!PackedKey(p[i], inverse_size, &key)) {
      continue;
    }
    if (seen->Insert(key)) out->push_back(i);
  }
}

}  // namespace

std::vector<size_t> RangeGatedVoxelIndices(const std::vector<Vec3>& points, double voxel_size,
                                           double min_range, double max_range, int threads) {
  std::vector<size_t> out;
  RangeGatedVoxelIndices(points, voxel_size, min_range, max_range, threads, &out);
  return out;
}

void RangeGatedVoxelIndices(const std::vector<Vec3>& points, double voxel_size, double min_range,
                            double max_range, int threads, std::vector<size_t>* out) {
  if (!(voxel_size > 0.0)) throw std::invalid_argument("RangeGatedVoxelIndices: voxel_size <= 0");
  out->clear();
  if (points.empty()) return;
  const double inverse_size = 1.0 / voxel_size;
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  // Reused across calls: fresh tables per sweep cost allocations and page faults.
  thread_local std::vector<PackedKeySet> seen_buffers;
  thread_local std::vector<std::vector<size_t>> kept_buffers;
  // The calling thread's buffers, by reference: in the workers the names above would denote
  // the workers' own (empty) thread_local instances.
  std::vector<PackedKeySet>& seen = seen_buffers;
  std::vector<std::vector<size_t>>& kept = kept_buffers;
  const size_t chunks = std::clamp<size_t>(static_cast<size_t>(std::max(threads, 1)), 1,
                                           std::max<size_t>(1, points.size() / 16384));
  if (seen.size() < chunks) seen.resize(chunks);
  if (kept.size() < chunks) kept.resize(chunks);
  // Each chunk keeps the first point of each voxel within the chunk; a point of chunk c is the
  // first of its voxel in the whole sweep iff no earlier chunk has that voxel. Same indices as
  // one pass, for any number of chunks.
  ParallelFor(static_cast<int>(chunks), points.size(), [&](size_t c, size_t begin, size_t end) {
    kept[c].clear();
    if (GateBoundsKey(max_range, inverse_size)) {
      FirstOfVoxelInBand<true>(points, begin, end, inverse_size, min2, max2, &seen[c], &kept[c]);
    } else {
      FirstOfVoxelInBand<false>(points, begin, end, inverse_size, min2, max2, &seen[c], &kept[c]);
    }
  });
  out->assign(kept[0].begin(), kept[0].end());
  for (size_t c = 1; c < chunks; ++c) {
    for (const size_t i : kept[c]) {
      uint64_t key;
      PackedKey(points[i], inverse_size, &key);
      bool earlier = false;
      for (size_t e = 0; e < c && !earlier; ++e) earlier = seen[e].Contains(key);
      if (!earlier) out->push_back(i);
    }
  }
}

double LidarFrontend::NextVoxelSize() const {
  return num_scans_ < options_.initial_scans ? options_.initial_voxel_size : options_.voxel_size;
}

namespace {

// Mean and (population) covariance of the neighbours' points; n > 0.
void MomentsOf(const std::vector<VoxelMap::Neighbour>& neighbours, Vec3* mean, Mat3* covariance) {
  const double n = static_cast<double>(neighbours.size());
  *mean = Vec3::Zero();
  for (const auto& nb : neighbours) *mean += nb.point;
  *mean /= n;
  *covariance = Mat3::Zero();
  for (const auto& nb : neighbours) {
    const Vec3 d = nb.point - *mean;
    covariance->noalias() += d * d.transpose();
  }
  *covariance /= n;
}

}  // namespace

bool FitPlane(const std::vector<VoxelMap::Neighbour>& neighbours, PlaneFit* plane) {
  if (neighbours.size() < 3) return false;
  Vec3 mean;
  Mat3 cov;
  MomentsOf(neighbours, &mean, &cov);
  return FitPlaneFromMoments(mean, cov, plane);
}

PlaneAssociator::PlaneAssociator(const VoxelMap& map, const LidarFrontendOptions& options)
    : map_(map), options_(options), voxel_planes_(options.association == "voxel_plane") {
  if (voxel_planes_ && !map.options().fit_planes) {
    throw std::invalid_argument(
        "PlaneAssociator: association voxel_plane needs a map that keeps its planes "
        "(VoxelMap::Options::fit_planes, set by LidarFrontend::MapOptions)");
  }
  neighbours_.reserve(options.max_neighbours);
}

bool PlaneAssociator::Associate(const Vec3& q_robot, const Vec3& p_map,
                                PlaneAssociation* association, double* thickness) {
  PlaneFit knn_plane;
  const PlaneFit* fit = &knn_plane;
  const VoxelPlane* voxel = voxel_planes_ ? map_.PlaneOf(p_map) : nullptr;
  if (voxel != nullptr && voxel->points >= options_.min_neighbours &&
      voxel->fit.sigma3 <= options_.voxel_plane_max_thickness) {
    fit = &voxel->fit;  // a hash lookup instead of the kNN search and the PCA
  } else {
    const int found = map_.KNearest(p_map, options_.max_neighbours, &neighbours_);
    if (found < options_.min_neighbours) return false;
    if (!FitPlane(neighbours_, &knn_plane)) return false;
    if (knn_plane.sigma2 < options_.line_neighbourhood_ratio * knn_plane.sigma1 &&
        !FitAcrossLine(p_map, &knn_plane)) {
      return false;
    }
    if (options_.max_plane_thickness > 0.0 && knn_plane.sigma3 > options_.max_plane_thickness) {
      return false;
    }
  }
  const PlaneFit& plane = *fit;
  const double distance = std::abs(plane.normal.dot(p_map - plane.centroid));
  if (!(distance <= options_.max_plane_distance)) return false;
  association->point_robot = q_robot;
  association->plane_point = plane.centroid;
  association->plane_normal = plane.normal;
  association->weight = plane.planarity_weight;
  if (thickness != nullptr) *thickness = plane.sigma3;
  return true;
}

bool PlaneAssociator::FitAcrossLine(const Vec3& p_map, PlaneFit* plane) {
  // The line's direction is the neighbours' largest principal axis; the two axes across it (the
  // kNN fit's normal and its middle axis, *plane on entry) are where another ring of the same
  // surface can lie, one ring spacing (1–2 m for a VLP-16's floor) away on either side.
  const Vec3 across[2] = {plane->normal, plane->middle_axis};
  const double step = map_.options().voxel_size;
  const double max_squared = 4.0 * step * step;  // within two map voxels of p_map
  wide_ = neighbours_;
  for (int axis = 0; axis < 2; ++axis) {
    for (const double side : {-1.0, 1.0}) {
      const Vec3 probe = p_map + side * step * across[axis];
      map_.KNearest(probe, options_.max_neighbours, &probe_);
      for (const auto& nb : probe_) {
        if ((nb.point - p_map).squaredNorm() > max_squared) continue;
        // The probes' neighbourhoods overlap each other's and the line's: each map point once,
        // or the overlap would weigh in the fit twice.
        const bool seen =
            std::any_of(wide_.begin(), wide_.end(),
                        [&](const VoxelMap::Neighbour& w) { return w.point == nb.point; });
        if (!seen) wide_.push_back(nb);
      }
    }
  }
  PlaneFit wide;
  if (!FitPlane(wide_, &wide)) return false;
  if (wide.sigma2 < options_.line_neighbourhood_ratio * wide.sigma1) return false;
  *plane = wide;
  return true;
}

VoxelMap::Options LidarFrontend::MapOptions(const LidarFrontendOptions& options) {
  VoxelMap::Options m;
  m.voxel_size = options.map_voxel_size;
  m.max_points_per_voxel = options.max_points_per_voxel;
  m.min_point_distance = options.min_point_distance;
  m.max_distance = options.max_map_distance;
  m.fit_planes = options.association == "voxel_plane";
  return m;
}

LidarFrontend::LidarFrontend(const LidarFrontendOptions& options)
    : options_(options), map_(MapOptions(options)) {
  options_.Validate();
}

std::vector<TimedPoint> LidarFrontend::Preprocess(const std::vector<TimedPoint>& sweep) {
  const double size = NextVoxelSize();
  ++num_scans_;
  return VoxelGridSubsample(RangeGate(sweep, options_.min_range, options_.max_range), size);
}

void LidarFrontend::SelectSweep(const std::vector<Vec3>& sweep_lidar, const SE3& T_robot_lidar,
                                SweepSelection* selection, int threads) {
  const double size = NextVoxelSize();
  ++num_scans_;
  selection->indices.clear();
  selection->points_robot.clear();
  selection->keypoints.clear();
  thread_local std::vector<size_t> first;  // reused: a fresh one per sweep faulted its pages in
  RangeGatedVoxelIndices(sweep_lidar, size, options_.min_range, options_.max_range,
                         threads > 0 ? threads : options_.threads, &first);
  selection->indices.reserve(first.size());
  selection->points_robot.reserve(first.size());
  // C·p + r with C = I, r = 0 is p itself for a finite p (1·x + 0·y + 0·z + 0 = x; −0 becomes +0,
  // the same voxel), so the robot-frame gate and subsampling would keep every survivor.
  // (r must be +0, not −0, for the bitwise equality below.)
  const Vec3& r = T_robot_lidar.translation();
  const bool identity = T_robot_lidar.rotation() == Mat3::Identity() && r == Vec3::Zero() &&
                        !std::signbit(r.x()) && !std::signbit(r.y()) && !std::signbit(r.z());
  // Reused across calls: fresh tables per sweep cost allocations and page faults.
  thread_local PackedKeySet robot_seen, keypoint_seen;
  robot_seen.Clear();
  keypoint_seen.Clear();
  const double inverse_size = 1.0 / size;
  const double inverse_keypoint_size = 1.0 / options_.keypoint_voxel_size;
  const double min2 = options_.min_range * options_.min_range;
  const double max2 = options_.max_range * options_.max_range;
  std::vector<size_t> candidates;  // keypoints before the max_keypoints cap
  // Every point reaching the keypoint voxels passed a range gate (|q| ≤ max_range), so their
  // keys need no bounds check when the gate implies it.
  const bool keypoint_key_in_range = GateBoundsKey(options_.max_range, inverse_keypoint_size);
  const auto keep = [&](size_t i, const Vec3& q) {
    uint64_t keypoint_key;  // Keypoints: VoxelGridSubsample of the preprocessed points
    bool valid = true;
    if (keypoint_key_in_range) {
      keypoint_key = PackedKeyInRange(q.x() * inverse_keypoint_size, q.y() * inverse_keypoint_size,
                                      q.z() * inverse_keypoint_size);
    } else {
      valid = PackedKey(q, inverse_keypoint_size, &keypoint_key);
    }
    if (valid && keypoint_seen.Insert(keypoint_key)) {
      candidates.push_back(selection->indices.size());
    }
    selection->indices.push_back(i);
    selection->points_robot.push_back(q);
  };
  if (identity) {
    // T·p is p + 0 here, bit for bit: each row sums x·1 and signed zeros, then adds r = +0, which
    // leaves x ≠ 0 unchanged and turns a zero of either sign into +0 — as p + 0 does.
    for (const size_t i : first) keep(i, sweep_lidar[i] + Vec3::Zero());
  } else {
    const bool key_in_range = GateBoundsKey(options_.max_range, inverse_size);
    for (const size_t i : first) {
      const Vec3 q = T_robot_lidar * sweep_lidar[i];
      // Preprocess: RangeGate, then VoxelGridSubsample.
      const double r2 = q.squaredNorm();
      if (!(r2 >= min2 && r2 <= max2)) continue;
      uint64_t key;
      if (key_in_range) {
        key = PackedKeyInRange(q.x() * inverse_size, q.y() * inverse_size, q.z() * inverse_size);
      } else if (!PackedKey(q, inverse_size, &key)) {
        continue;
      }
      if (robot_seen.Insert(key)) keep(i, q);
    }
  }
  // Keypoints' evenly spaced subset.
  const size_t cap = static_cast<size_t>(options_.max_keypoints);
  if (cap == 0 || candidates.size() <= cap) {
    selection->keypoints.swap(candidates);
    return;
  }
  selection->keypoints.reserve(cap);
  for (size_t i = 0; i < cap; ++i) {
    selection->keypoints.push_back(candidates[i * candidates.size() / cap]);
  }
}

std::vector<TimedPoint> KeypointsOf(const std::vector<TimedPoint>& preprocessed,
                                    double keypoint_voxel_size, int max_keypoints) {
  std::vector<TimedPoint> keypoints = VoxelGridSubsample(preprocessed, keypoint_voxel_size);
  const size_t cap = static_cast<size_t>(std::max(max_keypoints, 0));
  if (cap == 0 || keypoints.size() <= cap) return keypoints;
  // Evenly spaced subset: index i·n/cap, i = 0..cap−1 (deterministic, keeps the firing order).
  std::vector<TimedPoint> kept;
  kept.reserve(cap);
  for (size_t i = 0; i < cap; ++i) kept.push_back(keypoints[i * keypoints.size() / cap]);
  return kept;
}

std::vector<TimedPoint> LidarFrontend::Keypoints(
    const std::vector<TimedPoint>& preprocessed) const {
  return KeypointsOf(preprocessed, options_.keypoint_voxel_size, options_.max_keypoints);
}

void LidarFrontend::UpdateMap(const std::vector<Vec3>& points_map, const Vec3& robot_position_map) {
  map_.Insert(points_map);
  // RemoveFar visits every voxel (tens of thousands): run it only once the robot has moved 5% of
  // max_map_distance since the last pass, so a voxel outlives the bound by at most that much.
  if (!removal_done_ ||
      (robot_position_map - last_removal_position_).norm() > 0.05 * options_.max_map_distance) {
    map_.RemoveFar(robot_position_map);
    last_removal_position_ = robot_position_map;
    removal_done_ = true;
  }
}

}  // namespace ctlio::lio
