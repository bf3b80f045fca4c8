#include "ctlio/solvers/lio/voxel_map.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace ctlio::lio {

namespace {

inline uint64_t HashOf(const VoxelKey& k) {
  return MixVoxelHash((static_cast<uint64_t>(static_cast<uint32_t>(k.x)) << 42) ^
                      (static_cast<uint64_t>(static_cast<uint32_t>(k.y)) << 21) ^
                      static_cast<uint64_t>(static_cast<uint32_t>(k.z)));
}

}  // namespace

VoxelMap::VoxelMap(const Options& options)
    : options_(options),
      inverse_voxel_size_(1.0 / options.voxel_size),
      min_distance2_(options.min_point_distance * options.min_point_distance),
      stride_(static_cast<size_t>(std::max(options.max_points_per_voxel, 1))),
      record_lines_((kHeaderBytes + stride_ * sizeof(Vec3) + sizeof(CacheLine) - 1) /
                    sizeof(CacheLine)) {
  if (!(options.voxel_size > 0.0) || options.max_points_per_voxel < 1 ||
      !(options.min_point_distance >= 0.0) || !(options.max_distance > 0.0)) {
    throw std::invalid_argument(
        "VoxelMap: need voxel_size > 0, max_points_per_voxel >= 1, min_point_distance >= 0, "
        "max_distance > 0");
  }
}

int32_t VoxelMap::Find(const VoxelKey& key) const {
  if (slots_.empty()) return kNoVoxel;
  const uint64_t mask = slots_.size() - 1;
  for (uint64_t s = HashOf(key) & mask;; s = (s + 1) & mask) {
    const int32_t voxel = slots_[s];
    if (voxel == kNoVoxel || HeaderOf(voxel)->key == key) return voxel;
  }
}

void VoxelMap::ConstructRecord(int32_t voxel, const VoxelKey& key) {
  if (static_cast<size_t>(voxel) >> kChunkBits >= pool_.size()) {
    pool_.emplace_back(new CacheLine[(size_t{1} << kChunkBits) * record_lines_]);
  }
  unsigned char* bytes = RecordOf(voxel)->bytes;
  new (bytes) VoxelHeader{key, 0};
  // Eigen's default constructor leaves the coordinates unset: this only begins the points'
  // lifetimes, it writes nothing.
  std::uninitialized_default_construct_n(reinterpret_cast<Vec3*>(bytes + kHeaderBytes), stride_);
}

int32_t VoxelMap::FindOrAdd(const VoxelKey& key) {
  if (2 * (num_voxels_ + 1) > slots_.size()) Rehash(2 * (num_voxels_ + 1));
  const uint64_t mask = slots_.size() - 1;
  for (uint64_t s = HashOf(key) & mask;; s = (s + 1) & mask) {
    int32_t& slot = slots_[s];
    if (slot != kNoVoxel) {
      if (HeaderOf(slot)->key == key) return slot;
      continue;
    }
    if (num_voxels_ >= static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
      throw std::length_error("VoxelMap: more than 2^31 voxels");
    }
    const int32_t voxel = static_cast<int32_t>(num_voxels_);
    ConstructRecord(voxel, key);
    ++num_voxels_;
    slot = voxel;
    if (options_.fit_planes) {
      moments_.emplace_back();
      planes_.emplace_back();
      changed_.push_back(0);
    }
    return voxel;
  }
}

void VoxelMap::Rehash(size_t min_slots) {
  size_t n = 1024;
  while (n < min_slots) n *= 2;
  slots_.assign(n, kNoVoxel);
  const uint64_t mask = n - 1;
  for (size_t i = 0; i < num_voxels_; ++i) {
    uint64_t s = HashOf(HeaderOf(static_cast<int32_t>(i))->key) & mask;
    while (slots_[s] != kNoVoxel) s = (s + 1) & mask;
    slots_[s] = static_cast<int32_t>(i);
  }
}

bool VoxelMap::Insert(const Vec3& p) {
  if (!p.allFinite()) return false;
  const bool kept = InsertInto(FindOrAdd(VoxelKeyOf(p, inverse_voxel_size_)), p);
  RefitChangedPlanes();
  return kept;
}

// Inline (only this file calls them, once per map point): the call overheads were a third of
// the insertion's instructions.
inline bool VoxelMap::HasPointCloserThanMin(const Vec3* points, int32_t n, const Vec3& p) const {
  int32_t i = 0;
#if defined(__SSE2__)
  // Two points per step (x86-64 always has SSE2; the points are packed x0 y0 z0 x1 y1 z1): the
  // same products and sums in the same order ((dx² + dy²) + dz², no FMA) as the scalar loop
  // below, so the same comparisons, in about half the instructions.
  const __m128d px = _mm_set1_pd(p.x()), py = _mm_set1_pd(p.y()), pz = _mm_set1_pd(p.z());
  const __m128d min2 = _mm_set1_pd(min_distance2_);
  for (; i + 2 <= n; i += 2) {
    const double* q = points[i].data();
    const __m128d a = _mm_loadu_pd(q), b = _mm_loadu_pd(q + 2), c = _mm_loadu_pd(q + 4);
    const __m128d dx = _mm_sub_pd(_mm_shuffle_pd(a, b, 2), px);  // x0, x1
    const __m128d dy = _mm_sub_pd(_mm_shuffle_pd(a, c, 1), py);  // y0, y1
    const __m128d dz = _mm_sub_pd(_mm_shuffle_pd(b, c, 2), pz);  // z0, z1
    const __m128d d2 =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)), _mm_mul_pd(dz, dz));
    if (_mm_movemask_pd(_mm_cmplt_pd(d2, min2)) != 0) return true;
  }
#endif
  for (; i < n; ++i) {
    const double dx = points[i].x() - p.x(), dy = points[i].y() - p.y(), dz = points[i].z() - p.z();
    if ((dx * dx + dy * dy) + dz * dz < min_distance2_) return true;
  }
  return false;
}

inline bool VoxelMap::InsertInto(int32_t voxel, const Vec3& p) {
  VoxelHeader& header = *HeaderOf(voxel);
  int32_t& count = header.count;
  if (count >= options_.max_points_per_voxel) return false;
  Vec3* points = BlockOf(voxel);
  if (HasPointCloserThanMin(points, count, p)) return false;
  points[count++] = p;
  ++num_points_;
  if (options_.fit_planes) {
    const VoxelKey& k = header.key;
    const Vec3 d = p - Vec3(k.x, k.y, k.z) * options_.voxel_size;
    Moments& m = moments_[voxel];
    m.sum += d;
    m.sq[0] += d.x() * d.x();
    m.sq[1] += d.x() * d.y();
    m.sq[2] += d.x() * d.z();
    m.sq[3] += d.y() * d.y();
    m.sq[4] += d.y() * d.z();
    m.sq[5] += d.z() * d.z();
    if (!changed_[voxel]) {
      changed_[voxel] = 1;
      changed_voxels_.push_back(voxel);
    }
  }
  return true;
}

void VoxelMap::RefitChangedPlanes() {
  for (const int32_t voxel : changed_voxels_) {
    changed_[voxel] = 0;
    const int32_t n = HeaderOf(voxel)->count;
    VoxelPlane& plane = planes_[voxel];
    plane.points = 0;
    if (n < 3) continue;
    // Mean and population covariance from the moments: E[d] and E[d·dᵀ] − E[d]·E[d]ᵀ, d relative
    // to the corner (|d| ≤ √3 voxel sizes, so the subtraction loses nothing that matters).
    const Moments& m = moments_[voxel];
    const double inv_n = 1.0 / n;
    const Vec3 mean_d = m.sum * inv_n;
    Mat3 cov;
    cov << m.sq[0], m.sq[1], m.sq[2], m.sq[1], m.sq[3], m.sq[4], m.sq[2], m.sq[4], m.sq[5];
    cov = cov * inv_n - mean_d * mean_d.transpose();
    const VoxelKey& k = HeaderOf(voxel)->key;
    if (FitPlaneFromMoments(Vec3(k.x, k.y, k.z) * options_.voxel_size + mean_d, cov, &plane.fit)) {
      plane.points = n;
    }
  }
  changed_voxels_.clear();
}

const VoxelPlane* VoxelMap::PlaneOf(const Vec3& p) const {
  if (!options_.fit_planes) return nullptr;
  const int32_t voxel = Find(VoxelKeyOf(p, inverse_voxel_size_));
  return voxel == kNoVoxel ? nullptr : &planes_[voxel];
}

size_t VoxelMap::Insert(const std::vector<Vec3>& points) {
  // Consecutive points of a sweep (neighbouring beams of one firing) often share a voxel: reuse
  // the previous lookup then (voxel indices stay valid when the table grows). Same result as
  // inserting the points one by one.
  size_t kept = 0;
  int32_t last_voxel = kNoVoxel;
  VoxelKey last_key;
  recent_.assign(size_t{1} << kRecentBits, RecentVoxel{});
  // Prefetching a few points ahead, as KNearest does for its neighbours: the slot of point
  // i + 2·kAhead, then (its slot cached by then) the record of point i + kAhead, so that a voxel's
  // record is in cache when its point is inserted. Hints only: the lookups below are unchanged.
  constexpr size_t kAhead = 8;
  const auto slot_of = [&](size_t j) -> const int32_t* {
    const Vec3& a = points[j];
    if (slots_.empty() || !a.allFinite()) return nullptr;
    return &slots_[HashOf(VoxelKeyOf(a, inverse_voxel_size_)) & (slots_.size() - 1)];
  };
  for (size_t i = 0; i < points.size(); ++i) {
#if defined(__GNUC__)
    if (i + 2 * kAhead < points.size()) {
      if (const int32_t* slot = slot_of(i + 2 * kAhead)) __builtin_prefetch(slot);
    }
    if (i + kAhead < points.size()) {
      const int32_t* slot = slot_of(i + kAhead);
      if (slot != nullptr && *slot != kNoVoxel) __builtin_prefetch(RecordOf(*slot));
    }
#endif
    const Vec3& p = points[i];
    if (!p.allFinite()) continue;
    const VoxelKey key = VoxelKeyOf(p, inverse_voxel_size_);
    if (last_voxel == kNoVoxel || !(key == last_key)) {
      RecentVoxel& recent = recent_[RecentSlot(key)];
      if (recent.voxel == kNoVoxel || !(recent.key == key)) recent = {key, FindOrAdd(key)};
      last_voxel = recent.voxel;
      last_key = key;
    }
    kept += InsertInto(last_voxel, p) ? 1 : 0;
  }
  RefitChangedPlanes();
  return kept;
}

size_t VoxelMap::RemoveFar(const Vec3& location) {
  // Compacts the surviving voxels to the front (in order) and rebuilds the table.
  const double max2 = options_.max_distance * options_.max_distance;
  size_t kept = 0;
  for (size_t i = 0; i < num_voxels_; ++i) {
    const VoxelHeader& header = *HeaderOf(static_cast<int32_t>(i));
    const VoxelKey& k = header.key;
    const Vec3 centre = (Vec3(k.x, k.y, k.z) + Vec3::Constant(0.5)) * options_.voxel_size;
    if ((centre - location).squaredNorm() > max2) {
      num_points_ -= static_cast<size_t>(header.count);
      continue;
    }
    if (kept != i) {
      *HeaderOf(static_cast<int32_t>(kept)) = header;
      std::copy_n(BlockOf(static_cast<int32_t>(i)), header.count,
                  BlockOf(static_cast<int32_t>(kept)));
      if (options_.fit_planes) {  // no refit pending: every Insert ends with one
        moments_[kept] = moments_[i];
        planes_[kept] = planes_[i];
      }
    }
    ++kept;
  }
  const size_t removed = num_voxels_ - kept;
  if (removed == 0) return 0;
  num_voxels_ = kept;
  if (options_.fit_planes) {
    moments_.resize(kept);
    planes_.resize(kept);
    changed_.resize(kept);
  }
  pool_.resize((kept + (size_t{1} << kChunkBits) - 1) >> kChunkBits);
  Rehash(2 * kept + 1);
  return removed;
}

int VoxelMap::KNearest(const Vec3& q, int k, std::vector<Neighbour>* out,
                       double max_distance) const {
  out->clear();
  if (k <= 0) return 0;
  if (out->capacity() < static_cast<size_t>(k)) out->reserve(k);
  const double max2 = max_distance * max_distance;
  const VoxelKey c = VoxelKeyOf(q, inverse_voxel_size_);
  // Visit the 27 voxels nearest-box first and skip a voxel once the k found so far are all
  // closer than its box: same result as visiting all of them, a fraction of the distance tests.
  const Vec3 local = q * inverse_voxel_size_ - Vec3(c.x, c.y, c.z);  // in [0, 1)³, voxel units
  std::array<std::pair<double, int>, 27> order;
  for (int i = 0; i < 27; ++i) {
    const int d[3] = {i / 9 - 1, (i / 3) % 3 - 1, i % 3 - 1};
    double box2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double gap = d[a] < 0 ? local[a] : (d[a] > 0 ? 1.0 - local[a] : 0.0);
      box2 += gap * gap;
    }
    order[i] = {box2 * options_.voxel_size * options_.voxel_size, i};
  }
  std::sort(order.begin(), order.end());
  // The first probe of each candidate's slot first, the record there prefetched: the records of
  // the few occupied neighbours then arrive together instead of one miss after the other as the
  // visit reaches them (the 4-byte slots are mostly cached, the records are not). An empty first
  // slot is a definite "no voxel" (linear probing); any other is resolved by Find when visited.
  std::array<VoxelKey, 27> keys;
  std::array<bool, 27> absent;
  int candidates = 0;
  if (!slots_.empty()) {
    const uint64_t mask = slots_.size() - 1;
    for (; candidates < 27 && order[candidates].first <= max2; ++candidates) {
      const int i = order[candidates].second;
      keys[candidates] = {c.x + i / 9 - 1, c.y + (i / 3) % 3 - 1, c.z + i % 3 - 1};
      const int32_t first = slots_[HashOf(keys[candidates]) & mask];
      absent[candidates] = first == kNoVoxel;
#if defined(__GNUC__)
      if (first != kNoVoxel) __builtin_prefetch(RecordOf(first));
#endif
    }
  }
  for (int v = 0; v < candidates; ++v) {
    const double box2 = order[v].first;
    if (static_cast<int>(out->size()) == k && box2 >= out->back().squared_distance) break;
    if (absent[v]) continue;
    const int32_t voxel = Find(keys[v]);
    if (voxel == kNoVoxel) continue;
    for (const Vec3& p : PointsOf(voxel)) {
      const double d2 = (p - q).squaredNorm();
      if (d2 > max2) continue;
      const int n = static_cast<int>(out->size());
      if (n == k && d2 >= out->back().squared_distance) continue;
      // Insertion into the sorted list (k ≤ a few tens: cheaper than a heap).
      if (n < k) out->push_back({p, d2});
      int j = static_cast<int>(out->size()) - 1;
      while (j > 0 && (*out)[j - 1].squared_distance > d2) {
        (*out)[j] = (*out)[j - 1];
        --j;
      }
      (*out)[j] = {p, d2};
    }
  }
  return static_cast<int>(out->size());
}

void VoxelMap::Clear() {
  slots_.clear();
  num_voxels_ = 0;
  pool_.clear();
  moments_.clear();
  planes_.clear();
  changed_.clear();
  changed_voxels_.clear();
  num_points_ = 0;
}

}  // namespace ctlio::lio
