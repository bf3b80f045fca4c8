#include "ctlio/solvers/lio/frontend.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

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

inline bool PackedKey(const Vec3& p, double inverse_size, uint64_t* key) {
  const double fx = std::floor(p.x() * inverse_size), fy = std::floor(p.y() * inverse_size),
               fz = std::floor(p.z() * inverse_size);
  const double lo = -static_cast<double>(kKeyOffset), hi = static_cast<double>(kKeyOffset - 1);
  if (!(fx >= lo && fx <= hi && fy >= lo && fy <= hi && fz >= lo && fz <= hi)) return false;
  const uint64_t x = static_cast<uint64_t>(static_cast<int64_t>(fx) + kKeyOffset);
  const uint64_t y = static_cast<uint64_t>(static_cast<int64_t>(fy) + kKeyOffset);
  const uint64_t z = static_cast<uint64_t>(static_cast<int64_t>(fz) + kKeyOffset);
  static_assert(3 * 21 < 64, "packed key must not collide with kEmpty");
  *key = (x * static_cast<uint64_t>(kKeyRange) + y) * static_cast<uint64_t>(kKeyRange) + z;
  return true;
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
    } else {
      std::fill(table_.begin(), table_.end(), kEmpty);
    }
    size_ = 0;
    last_ = kEmpty;
  }
  // Inserts key; returns whether it was new.
  bool Insert(uint64_t key) {
    // Consecutive returns of a firing mostly fall in the voxel of the previous one, which is in
    // the set by then: answer without hashing or probing.
    if (key == last_) return false;
    last_ = key;
    if (2 * (size_ + 1) > table_.size()) Grow();
    for (uint64_t slot = MixVoxelHash(key) & mask_;; slot = (slot + 1) & mask_) {
      if (table_[slot] == key) return false;
      if (table_[slot] == kEmpty) {
        table_[slot] = key;
        ++size_;
        return true;
      }
    }
  }

 private:
  static constexpr size_t kInitialCapacity = 4096;
  void Grow() {
    spare_.assign(2 * table_.size(), kEmpty);
    const uint64_t mask = spare_.size() - 1;
    for (const uint64_t key : table_) {
      if (key == kEmpty) continue;
      uint64_t slot = MixVoxelHash(key) & mask;
      while (spare_[slot] != kEmpty) slot = (slot + 1) & mask;
      spare_[slot] = key;
    }
    table_.swap(spare_);
    mask_ = mask;
  }
  std::vector<uint64_t> table_, spare_;
  uint64_t mask_ = 0;
  size_t size_ = 0;
  uint64_t last_ = kEmpty;  // the key of the previous Insert
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

std::vector<size_t> RangeGatedVoxelIndices(const std::vector<Vec3>& points, double voxel_size,
                                           double min_range, double max_range) {
  if (!(voxel_size > 0.0)) throw std::invalid_argument("RangeGatedVoxelIndices: voxel_size <= 0");
  std::vector<size_t> out;
  if (points.empty()) return out;
  thread_local PackedKeySet seen;
  seen.Clear();
  const double inverse_size = 1.0 / voxel_size;
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  for (size_t i = 0; i < points.size(); ++i) {
    const double r2 = points[i].squaredNorm();
    if (!(r2 >= min2 && r2 <= max2)) continue;  // also drops non-finite points
    uint64_t key;
    if (!PackedKey(points[i], inverse_size, &key)) continue;
    if (seen.Insert(key)) out.push_back(i);
  }
  return out;
}

double LidarFrontend::NextVoxelSize() const {
  return num_scans_ < options_.initial_scans ? options_.initial_voxel_size : options_.voxel_size;
}

bool FitPlane(const std::vector<VoxelMap::Neighbour>& neighbours, PlaneFit* plane) {
  const size_t n = neighbours.size();
  if (n < 3) return false;
  Vec3 mean = Vec3::Zero();
  for (const auto& nb : neighbours) mean += nb.point;
  mean /= static_cast<double>(n);
  Mat3 cov = Mat3::Zero();
  for (const auto& nb : neighbours) {
    const Vec3 d = nb.point - mean;
    cov.noalias() += d * d.transpose();
  }
  cov /= static_cast<double>(n);
  // Closed-form 3×3 eigen-decomposition (several times faster than the iterative QL solver;
  // the plane normal's eigenvalue is well separated for the planar patches that pass the gate).
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(cov);
  if (es.info() != Eigen::Success) return false;
  // Eigenvalues ascending: λ0 ≤ λ1 ≤ λ2, σ1 = √λ2 ≥ σ2 = √λ1 ≥ σ3 = √λ0.
  const Vec3 lambda = es.eigenvalues().cwiseMax(0.0);
  plane->sigma1 = std::sqrt(lambda[2]);
  plane->sigma2 = std::sqrt(lambda[1]);
  plane->sigma3 = std::sqrt(lambda[0]);
  if (!(plane->sigma1 > 0.0)) return false;
  const double a2d = (plane->sigma2 - plane->sigma3) / plane->sigma1;
  plane->planarity_weight = a2d * a2d;
  plane->centroid = mean;
  plane->normal = es.eigenvectors().col(0).normalized();
  return true;
}

PlaneAssociator::PlaneAssociator(const VoxelMap& map, const LidarFrontendOptions& options)
    : map_(map), options_(options) {
  neighbours_.reserve(options.max_neighbours);
}

bool PlaneAssociator::Associate(const Vec3& q_robot, const Vec3& p_map,
                                PlaneAssociation* association) {
  const int found = map_.KNearest(p_map, options_.max_neighbours, &neighbours_);
  if (found < options_.min_neighbours) return false;
  PlaneFit plane;
  if (!FitPlane(neighbours_, &plane)) return false;
  const double distance = std::abs(plane.normal.dot(p_map - plane.centroid));
  if (!(distance <= options_.max_plane_distance)) return false;
  association->point_robot = q_robot;
  association->plane_point = plane.centroid;
  association->plane_normal = plane.normal;
  association->weight = plane.planarity_weight;
  return true;
}

VoxelMap::Options LidarFrontend::MapOptions(const LidarFrontendOptions& options) {
  VoxelMap::Options m;
  m.voxel_size = options.map_voxel_size;
  m.max_points_per_voxel = options.max_points_per_voxel;
  m.min_point_distance = options.min_point_distance;
  m.max_distance = options.max_map_distance;
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

std::vector<TimedPoint> LidarFrontend::Keypoints(
    const std::vector<TimedPoint>& preprocessed) const {
  std::vector<TimedPoint> keypoints =
      VoxelGridSubsample(preprocessed, options_.keypoint_voxel_size);
  const size_t cap = static_cast<size_t>(options_.max_keypoints);
  if (cap == 0 || keypoints.size() <= cap) return keypoints;
  // Evenly spaced subset: index i·n/cap, i = 0..cap−1 (deterministic, keeps the firing order).
  std::vector<TimedPoint> kept;
  kept.reserve(cap);
  for (size_t i = 0; i < cap; ++i) kept.push_back(keypoints[i * keypoints.size() / cap]);
  return kept;
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
