#include "ctlio/eval/point_odometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace ctlio::eval {
namespace {

uint64_t VoxelKey(const Vec3& p, double voxel) {
  const auto key = [&](int i) { return uint64_t(int64_t(std::floor(p[i] / voxel)) & 0x1FFFFF); };
  return key(0) | key(1) << 21 | key(2) << 42;
}

// One original point per voxel, the first (as KISS-ICP keeps).
std::vector<Vec3> FirstPerVoxel(const std::vector<Vec3>& points, double voxel) {
  std::unordered_set<uint64_t> seen;
  std::vector<Vec3> out;
  for (const Vec3& p : points) {
    if (seen.insert(VoxelKey(p, voxel)).second) out.push_back(p);
  }
  return out;
}

}  // namespace

PointOdometry::PointOdometry(const SE3& first, const PointOdometryOptions& options,
                             const SE3& motion)
    : options_(options), first_(first), motion_(motion) {}

size_t PointOdometry::MapSize() const {
  size_t n = 0;
  for (const auto& [key, v] : map_) n += v.points.size();
  return n;
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
  const std::vector<Vec3> frame = FirstPerVoxel(deskewed, 0.5 * options_.map_voxel);
  SE3 pose = first_;
  if (k > 0) {
    // Registered in the previous sweep's frame: with world coordinates of a hundred metres the
    // rotation and translation of the left perturbation couple badly (point_icp.h).
    const SE3 previous_inv = poses_[k - 1].Inverse();
    std::vector<Vec3> target;
    target.reserve(MapSize());
    for (const auto& [key, v] : map_) {
      for (const Vec3& p : v.points) target.push_back(previous_inv * p);
    }
    PointIcpOptions icp;
    icp.source_voxel = 0.0;  // downsampled here
    icp.gates = options_.gates;
    icp.damping = options_.damping;
    pose = poses_[k - 1] *
           RegisterPointToPoint(FirstPerVoxel(frame, options_.source_voxel), target, delta, icp)
               .target_from_source;
  }
  poses_.push_back(pose);
  std::vector<Vec3> world;
  world.reserve(frame.size());
  for (const Vec3& p : frame) world.push_back(pose * p);
  AddToMap(world, pose.translation());
  return pose;
}

void PointOdometry::AddToMap(const std::vector<Vec3>& world_points, const Vec3& sensor) {
  std::unordered_map<uint64_t, size_t> index;
  for (size_t i = 0; i < map_.size(); ++i) index[map_[i].first] = i;
  for (const Vec3& p : world_points) {
    const uint64_t key = VoxelKey(p, options_.map_voxel);
    const auto it = index.find(key);
    if (it == index.end()) {
      index[key] = map_.size();
      map_.push_back({key, Voxel{{p}}});
    } else if (int(map_[it->second].second.points.size()) < options_.max_points_per_voxel) {
      map_[it->second].second.points.push_back(p);
    }
  }
  // Forget what is out of reach (the first point of a voxel stands for it).
  const double r2 = options_.map_radius * options_.map_radius;
  map_.erase(std::remove_if(map_.begin(), map_.end(),
                            [&](const auto& kv) {
                              return (kv.second.points.front() - sensor).squaredNorm() > r2;
                            }),
             map_.end());
}

}  // namespace ctlio::eval
