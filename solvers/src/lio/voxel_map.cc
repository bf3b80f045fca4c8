#include "ctlio/solvers/lio/voxel_map.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace ctlio::lio {

VoxelMap::VoxelMap(const Options& options)
    : options_(options),
      inverse_voxel_size_(1.0 / options.voxel_size),
      min_distance2_(options.min_point_distance * options.min_point_distance) {
  if (!(options.voxel_size > 0.0) || options.max_points_per_voxel < 1 ||
      !(options.min_point_distance >= 0.0) || !(options.max_distance > 0.0)) {
    throw std::invalid_argument(
        "VoxelMap: need voxel_size > 0, max_points_per_voxel >= 1, min_point_distance >= 0, "
        "max_distance > 0");
  }
}

bool VoxelMap::Insert(const Vec3& p) {
  if (!p.allFinite()) return false;
  return InsertInto(&voxels_[VoxelKeyOf(p, inverse_voxel_size_)], p);
}

bool VoxelMap::InsertInto(Voxel* voxel, const Vec3& p) {
  if (static_cast<int>(voxel->points.size()) >= options_.max_points_per_voxel) return false;
  for (const Vec3& existing : voxel->points) {
    if ((existing - p).squaredNorm() < min_distance2_) return false;
  }
  if (voxel->points.empty()) voxel->points.reserve(options_.max_points_per_voxel);
  voxel->points.push_back(p);
  ++num_points_;
  return true;
}

size_t VoxelMap::Insert(const std::vector<Vec3>& points) {
  // Consecutive points of a sweep (neighbouring beams of one firing) often share a voxel: reuse
  // the previous hash-map lookup then (element pointers of std::unordered_map stay valid when
  // it rehashes). Same result as inserting the points one by one.
  size_t kept = 0;
  Voxel* last_voxel = nullptr;
  VoxelKey last_key;
  for (const Vec3& p : points) {
    if (!p.allFinite()) continue;
    const VoxelKey key = VoxelKeyOf(p, inverse_voxel_size_);
    if (last_voxel == nullptr || !(key == last_key)) {
      last_voxel = &voxels_[key];
      last_key = key;
    }
    kept += InsertInto(last_voxel, p) ? 1 : 0;
  }
  return kept;
}

size_t VoxelMap::RemoveFar(const Vec3& location) {
  const double max2 = options_.max_distance * options_.max_distance;
  size_t removed = 0;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    const Vec3 centre =
        (Vec3(it->first.x, it->first.y, it->first.z) + Vec3::Constant(0.5)) * options_.voxel_size;
    if ((centre - location).squaredNorm() > max2) {
      num_points_ -= it->second.points.size();
      it = voxels_.erase(it);
      ++removed;
    } else {
      ++it;
    }
  }
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
  for (const auto& [box2, i] : order) {
    if (box2 > max2) break;
    if (static_cast<int>(out->size()) == k && box2 >= out->back().squared_distance) break;
    const auto it = voxels_.find({c.x + i / 9 - 1, c.y + (i / 3) % 3 - 1, c.z + i % 3 - 1});
    if (it == voxels_.end()) continue;
    for (const Vec3& p : it->second.points) {
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
  voxels_.clear();
  num_points_ = 0;
}

}  // namespace ctlio::lio
