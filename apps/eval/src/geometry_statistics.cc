#include "ctlio/eval/geometry_statistics.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <queue>
#include <stdexcept>
#include <unordered_map>

namespace ctlio::eval {
namespace {

struct VoxelKey {
  int64_t x, y, z;
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct VoxelKeyHash {
  size_t operator()(const VoxelKey& k) const {
    return size_t(k.x * 73856093) ^ size_t(k.y * 19349669) ^ size_t(k.z * 83492791);
  }
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace

std::vector<Vec3> VoxelCentroids(const std::vector<Vec3>& points, double voxel) {
  std::unordered_map<VoxelKey, size_t, VoxelKeyHash> index;
  index.reserve(points.size());
  std::vector<Vec3> sum;
  std::vector<int> count;
  for (const Vec3& p : points) {
    const VoxelKey key{int64_t(std::floor(p.x() / voxel)), int64_t(std::floor(p.y() / voxel)),
                       int64_t(std::floor(p.z() / voxel))};
    const auto [it, added] = index.emplace(key, sum.size());
    if (added) {
      sum.push_back(Vec3::Zero());
      count.push_back(0);
    }
    sum[it->second] += p;
    ++count[it->second];
  }
  for (size_t i = 0; i < sum.size(); ++i) sum[i] /= double(count[i]);
  return sum;
}

KdTree::KdTree(std::vector<Vec3> points) : points_(std::move(points)) {
  std::vector<int> order(points_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  nodes_.reserve(points_.size());
  root_ = Build(order, 0, int(order.size()), 0);
}

int KdTree::Build(std::vector<int>& order, int lo, int hi, int depth) {
  if (lo >= hi) return -1;
  // Split on the axis of largest extent at the median (a balanced tree whatever the cloud).
  Vec3 mn = Vec3::Constant(1e300), mx = Vec3::Constant(-1e300);
  for (int i = lo; i < hi; ++i) {
    mn = mn.cwiseMin(points_[order[i]]);
    mx = mx.cwiseMax(points_[order[i]]);
  }
  int axis = 0;
  (mx - mn).maxCoeff(&axis);
  const int mid = (lo + hi) / 2;
  std::nth_element(order.begin() + lo, order.begin() + mid, order.begin() + hi,
                   [&](int a, int b) { return points_[a][axis] < points_[b][axis]; });
  const int node = int(nodes_.size());
  nodes_.push_back({order[mid], axis, -1, -1});
  const int left = Build(order, lo, mid, depth + 1);
  const int right = Build(order, mid + 1, hi, depth + 1);
  nodes_[node].left = left;
  nodes_[node].right = right;
  return node;
}

void KdTree::Nearest(const Vec3& q, int k, std::vector<int>* indices,
                     std::vector<double>* squared_distances) const {
  indices->clear();
  if (squared_distances) squared_distances->clear();
  if (k <= 0 || root_ < 0) return;
  // Max-heap of the best k so far: (squared distance, index).
  std::priority_queue<std::pair<double, int>> best;
  auto visit = [&](auto&& self, int n) -> void {
    if (n < 0) return;
    const Node& node = nodes_[n];
    const Vec3& p = points_[node.point];
    const double d2 = (p - q).squaredNorm();
    if (int(best.size()) < k) {
      best.emplace(d2, node.point);
    } else if (d2 < best.top().first) {
      best.pop();
      best.emplace(d2, node.point);
    }
    const double diff = q[node.axis] - p[node.axis];
    const int near = diff < 0 ? node.left : node.right, far = diff < 0 ? node.right : node.left;
    self(self, near);
    if (int(best.size()) < k || diff * diff < best.top().first) self(self, far);
  };
  visit(visit, root_);
  indices->resize(best.size());
  if (squared_distances) squared_distances->resize(best.size());
  for (int i = int(best.size()) - 1; i >= 0; --i) {
    (*indices)[i] = best.top().second;
    if (squared_distances) (*squared_distances)[i] = best.top().first;
    best.pop();
  }
}

GeometryStatistics ComputeGeometryStatistics(const std::vector<Vec3>& points,
                                             const GeometryOptions& o) {
  if (!(o.min_range >= 0.0 && o.max_range > o.min_range && o.voxel > 0.0 && o.neighbours >= 3)) {
    throw std::invalid_argument(
        "geometry statistics: need 0 <= min_range < max_range, voxel > 0, neighbours >= 3");
  }
  GeometryStatistics s;
  std::vector<Vec3> kept;
  kept.reserve(points.size());
  for (const Vec3& p : points) {
    const double r = p.norm();
    if (r >= o.min_range && r <= o.max_range) kept.push_back(p);
  }
  s.points = kept.size();
  std::vector<Vec3> voxels = VoxelCentroids(kept, o.voxel);
  s.downsampled = voxels.size();
  std::vector<double> ranges;
  ranges.reserve(voxels.size());
  for (const Vec3& p : voxels) ranges.push_back(p.norm());
  s.median_range = Median(ranges);
  if (int(voxels.size()) < o.neighbours) return s;
  const KdTree tree(std::move(voxels));
  std::vector<int> nn;
  std::vector<double> ratios;
  ratios.reserve(tree.points().size());
  size_t planar = 0, scattered = 0;
  for (const Vec3& p : tree.points()) {
    tree.Nearest(p, o.neighbours, &nn);
    Vec3 mean = Vec3::Zero();
    for (int i : nn) mean += tree.points()[i];
    mean /= double(nn.size());
    Mat3 cov = Mat3::Zero();
    for (int i : nn) {
      const Vec3 e = tree.points()[i] - mean;
      cov += e * e.transpose();
    }
    cov /= double(nn.size());
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov, Eigen::EigenvaluesOnly);
    const Vec3 lambda = eig.eigenvalues();  // ascending
    const double ratio = lambda[2] > 0.0 ? std::max(lambda[0], 0.0) / lambda[2] : 0.0;
    ratios.push_back(ratio);
    if (ratio < o.planar_below) ++planar;
    if (ratio > o.scattered_above) ++scattered;
  }
  s.planar = double(planar) / double(ratios.size());
  s.scattered = double(scattered) / double(ratios.size());
  s.median_ratio = Median(ratios);
  return s;
}

void WriteGeometryHeader(std::ostream& os) {
  os << "sweep                                     points  voxels  planar  scattered  "
        "median_ratio  median_range_m\n";
}

void WriteGeometryRow(std::ostream& os, const std::string& label, const GeometryStatistics& s) {
  char line[256];
  std::snprintf(line, sizeof(line), "%-40s %7zu %7zu   %5.3f      %5.3f        %6.4f         %5.1f",
                label.c_str(), s.points, s.downsampled, s.planar, s.scattered, s.median_ratio,
                s.median_range);
  os << line << "\n";
}

}  // namespace ctlio::eval
