#include "lio/map_accumulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ctlio::lioapp {

namespace {

constexpr size_t kInitialSlots = 1024;
constexpr int64_t kHalfRange = int64_t{1} << 20;

// Fibonacci hashing: the top log2(slots) bits of the key times 2^64/φ, which mix every bit of
// the three packed coordinates (neighbouring voxels differ in the low bits of one field only).
size_t Slot(uint64_t key, size_t slots) {
  const int bits = __builtin_ctzll(slots);  // slots is a power of two ≥ 1024
  return static_cast<size_t>((key * 0x9E3779B97F4A7C15ULL) >> (64 - bits));
}

}  // namespace

MapAccumulator::MapAccumulator(double voxel_size, size_t max_points)
    : voxel_size_(voxel_size), inv_voxel_size_(1.0 / voxel_size), max_points_(max_points) {
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size)) {
    throw std::invalid_argument("map voxel size must be a finite number > 0, got " +
                                std::to_string(voxel_size));
  }
  keys_.assign(kInitialSlots, kEmpty);
  cells_.resize(kInitialSlots);
  peak_bytes_ = bytes();
}

size_t MapAccumulator::bytes() const {
  return keys_.size() * sizeof(uint64_t) + cells_.size() * sizeof(Cell);
}

size_t MapAccumulator::Find(uint64_t key) const {
  const size_t mask = keys_.size() - 1;
  size_t i = Slot(key, keys_.size());
  while (keys_[i] != kEmpty && keys_[i] != key) {
    i = (i + 1) & mask;  // linear probing
  }
  return i;
}

void MapAccumulator::Grow() {
  std::vector<uint64_t> old_keys(keys_.size() * 2, kEmpty);
  std::vector<Cell> old_cells(cells_.size() * 2);
  old_keys.swap(keys_);
  old_cells.swap(cells_);
  peak_bytes_ = std::max(
      peak_bytes_, bytes() + old_keys.size() * sizeof(uint64_t) + old_cells.size() * sizeof(Cell));
  for (size_t i = 0; i < old_keys.size(); ++i) {
    if (old_keys[i] == kEmpty) {
      continue;
    }
    const size_t j = Find(old_keys[i]);
    keys_[j] = old_keys[i];
    cells_[j] = old_cells[i];
  }
}

void MapAccumulator::Add(const std::vector<Vec3>& points, const SE3& T) {
  const Mat3& R = T.rotation();
  const Vec3& t = T.translation();
  for (const Vec3& p_in : points) {
    ++added_;
    const Vec3 p = R * p_in + t;
    int64_t index[3];
    bool inside = p.allFinite();
    for (int k = 0; k < 3 && inside; ++k) {
      const double v = std::floor(p[k] * inv_voxel_size_);
      inside = v >= static_cast<double>(-kHalfRange) && v < static_cast<double>(kHalfRange);
      index[k] = inside ? static_cast<int64_t>(v) : 0;
    }
    if (!inside) {
      ++dropped_range_;
      continue;
    }
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      key = (key << kBits) | static_cast<uint64_t>(index[k] + kHalfRange);
    }
    size_t slot = Find(key);
    if (keys_[slot] == kEmpty) {
      if (max_points_ > 0 && size_ >= max_points_) {
        ++dropped_cap_;
        continue;
      }
      if (10 * (size_ + 1) > 7 * keys_.size()) {  // load ≤ 0.7 keeps the probes short
        Grow();
        slot = Find(key);
      }
      keys_[slot] = key;
      cells_[slot] = Cell{};
      ++size_;
    }
    // Running mean about the voxel centre: c_n = c_{n−1} + (x − c_{n−1}) / n.
    Cell& c = cells_[slot];
    c.n += 1;
    const float w = 1.0f / static_cast<float>(c.n);
    c.dx +=
        (static_cast<float>(p.x() - (static_cast<double>(index[0]) + 0.5) * voxel_size_) - c.dx) *
        w;
    c.dy +=
        (static_cast<float>(p.y() - (static_cast<double>(index[1]) + 0.5) * voxel_size_) - c.dy) *
        w;
    c.dz +=
        (static_cast<float>(p.z() - (static_cast<double>(index[2]) + 0.5) * voxel_size_) - c.dz) *
        w;
  }
}

void MapAccumulator::Clear() {
  std::fill(keys_.begin(), keys_.end(), kEmpty);
  size_ = added_ = dropped_cap_ = dropped_range_ = 0;
}

std::vector<Vec3> MapAccumulator::Points() const {
  std::vector<Vec3> out;
  out.reserve(size_);
  const uint64_t field = (uint64_t{1} << kBits) - 1;
  for (size_t i = 0; i < keys_.size(); ++i) {
    const uint64_t key = keys_[i];
    if (key == kEmpty) {
      continue;
    }
    const Cell& c = cells_[i];
    const double ix =
        static_cast<double>(static_cast<int64_t>((key >> (2 * kBits)) & field) - kHalfRange);
    const double iy =
        static_cast<double>(static_cast<int64_t>((key >> kBits) & field) - kHalfRange);
    const double iz = static_cast<double>(static_cast<int64_t>(key & field) - kHalfRange);
    out.emplace_back((ix + 0.5) * voxel_size_ + c.dx, (iy + 0.5) * voxel_size_ + c.dy,
                     (iz + 0.5) * voxel_size_ + c.dz);
  }
  return out;
}

}  // namespace ctlio::lioapp
