#include "ctlio/eval/point_odometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "ctlio/eval/point_to_point.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::eval {
namespace {

std::array<int64_t, 3> VoxelOf(const Vec3& p, double voxel) {
  return {int64_t(std::floor(p.x() / voxel)), int64_t(std::floor(p.y() / voxel)),
          int64_t(std::floor(p.z() / voxel))};
}

uint64_t Key(const std::array<int64_t, 3>& v) {
  return (uint64_t(v[0]) & 0x1FFFFF) | (uint64_t(v[1]) & 0x1FFFFF) << 21 |
         (uint64_t(v[2]) & 0x1FFFFF) << 42;
}

}  // namespace

double AdaptiveThreshold::Update(const SE3& deviation) {
  const double theta = deviation.Log().tail<3>().norm();
  const double delta = deviation.translation().norm() + 2.0 * max_range_ * std::sin(0.5 * theta);
  if (delta > min_motion_) {
    sum_squares_ += delta * delta;
    ++samples_;
  }
  return delta;
}

double AdaptiveThreshold::Sigma() const {
  return samples_ == 0 ? initial_ : std::sqrt(sum_squares_ / samples_);
}

PointOdometry::PointOdometry(const SE3& first, const PointOdometryOptions& options,
                             const SE3& motion)
    : options_(options),
      first_(first),
      motion_(motion),
      threshold_(options.initial_sigma, options.min_motion, options.max_range) {}

size_t PointOdometry::MapSize() const {
  size_t n = 0;
  for (const Voxel& v : map_) n += v.points.size();
  return n;
}

const Vec3* PointOdometry::Nearest(const Vec3& p, double max_distance) const {
  // KISS-ICP's search: the 3 × 3 × 3 map voxels around p's, so a correspondence is never
  // farther than two voxels whatever the threshold.
  const std::array<int64_t, 3> c = VoxelOf(p, options_.map_voxel);
  const Vec3* best = nullptr;
  double best_d2 = max_distance * max_distance;
  for (int64_t dx = -1; dx <= 1; ++dx) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      for (int64_t dz = -1; dz <= 1; ++dz) {
        const auto it = index_.find(Key({c[0] + dx, c[1] + dy, c[2] + dz}));
        if (it == index_.end()) continue;
        for (const Vec3& q : map_[it->second].points) {
          const double d2 = (q - p).squaredNorm();
          if (d2 < best_d2) {
            best_d2 = d2;
            best = &q;
          }
        }
      }
    }
  }
  return best;
}

SE3 PointOdometry::Align(const std::vector<Vec3>& source, const SE3& previous, const SE3& initial,
                         double sigma) const {
  // Unknown T = T_{k−1}⁻¹·T_k (the sweep in the previous sweep's frame), perturbed on the left,
  // T ← Exp(δ)·T: with world coordinates of a hundred metres a perturbation about the world
  // origin would couple rotation and translation badly. For q = T·s the world point is
  // p = T_{k−1}·q, e = p − m (m its map neighbour), ∂e/∂δ = R_{k−1}·[I, −q^].
  const double gate = 3.0 * sigma, kernel = sigma / 3.0;
  const Mat3 R = previous.rotation();
  SE3 T = initial;
  for (int it = 0; it < options_.iterations; ++it) {
    PointToPointSystem system;
    for (const Vec3& s : source) {
      const Vec3 q = T * s;
      const Vec3 p = previous * q;
      const Vec3* m = Nearest(p, gate);
      if (m == nullptr) continue;
      const Vec3 e = p - *m;
      Eigen::Matrix<double, 3, 6> J;
      J << R, -R * so3::Hat(q);
      system.Add(e, J, kernel);
    }
    if (system.used() < 6) break;
    const Vec6 delta = system.Step();
    if (!delta.allFinite()) break;
    T = SE3::Exp(delta) * T;
    if (delta.norm() < options_.converged) break;
  }
  return T;
}

SE3 PointOdometry::Register(const std::vector<Vec3>& points, const std::vector<double>& times,
                            double period) {
  if (points.size() != times.size() || !(period > 0.0)) {
    throw std::invalid_argument("PointOdometry::Register: one time per point and a period > 0");
  }
  const size_t k = poses_.size();
  const SE3 delta = k >= 2 ? poses_[k - 2].Inverse() * poses_[k - 1] : motion_;
  const Vec6 xi = delta.Log();
  std::vector<Vec3> deskewed;
  deskewed.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const double r = points[i].norm();
    if (r < options_.min_range || r > options_.max_range) continue;
    deskewed.push_back(options_.deskew ? SE3::Exp((times[i] / period) * xi) * points[i]
                                       : points[i]);
  }
  const std::vector<Vec3> frame = FirstPointPerVoxel(deskewed, 0.5 * options_.map_voxel);
  SE3 pose = first_;
  double sigma = 0.0;
  if (k > 0) {
    sigma = options_.fixed_sigma > 0.0 ? options_.fixed_sigma : threshold_.Sigma();
    const SE3 relative =
        Align(FirstPointPerVoxel(frame, options_.source_voxel), poses_[k - 1], delta, sigma);
    // The prediction's error, D = (T_{k−1}·Δ)⁻¹·T_k = Δ⁻¹·relative.
    threshold_.Update(delta.Inverse() * relative);
    pose = poses_[k - 1] * relative;
    // Back onto SO(3): the constant-velocity recurrence T_k ≈ T_{k−1}·(T_{k−2}⁻¹·T_{k−1}), with
    // the inverse taken as the transpose, multiplies a rotation matrix's deviation from
    // orthogonality by 1 + √2 per sweep (ε_k = 2ε_{k−1} + ε_{k−2}): rounding errors of 1e-16 grew
    // to 1e-2 after 35 sweeps and every run left the track after 38–42 sweeps, whatever the world,
    // speed or stride (docs/experiments/worlds-geometry.md).
    pose = SE3(pose.quaternion(), pose.translation());
  }
  poses_.push_back(pose);
  sigmas_.push_back(sigma);
  std::vector<Vec3> world;
  world.reserve(frame.size());
  for (const Vec3& p : frame) world.push_back(pose * p);
  AddToMap(world, pose.translation());
  return pose;
}

void PointOdometry::AddToMap(const std::vector<Vec3>& world_points, const Vec3& sensor) {
  for (const Vec3& p : world_points) {
    const uint64_t key = Key(VoxelOf(p, options_.map_voxel));
    const auto it = index_.find(key);
    if (it == index_.end()) {
      index_[key] = map_.size();
      map_.push_back(Voxel{key, {p}});
    } else if (int(map_[it->second].points.size()) < options_.max_points_per_voxel) {
      map_[it->second].points.push_back(p);
    }
  }
  // Forget what is out of reach (the first point of a voxel stands for it).
  const double r2 = options_.map_radius * options_.map_radius;
  const size_t before = map_.size();
  map_.erase(std::remove_if(
                 map_.begin(), map_.end(),
                 [&](const Voxel& v) { return (v.points.front() - sensor).squaredNorm() > r2; }),
             map_.end());
  if (map_.size() != before) {
    index_.clear();
    for (size_t i = 0; i < map_.size(); ++i) index_[map_[i].key] = i;
  }
}

}  // namespace ctlio::eval
