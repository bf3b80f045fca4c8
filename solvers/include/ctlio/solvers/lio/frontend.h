// Lidar front end (SPEC §4, as in CT-ICP and the reference implementation): range gate, voxel
// subsampling, keypoint selection, and the association of a point with a plane of the voxel map
// (k nearest neighbours, PCA plane, planarity weight, distance gate).
#pragma once

#include <vector>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/types.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"
#include "ctlio/solvers/lio/plane_fit.h"
#include "ctlio/solvers/lio/voxel_map.h"

namespace ctlio::lio {

// One lidar return: position in the sensor/robot frame and time in seconds (relative to any
// origin the caller chooses, the same as the knot times it registers against).
struct TimedPoint {
  Vec3 point = Vec3::Zero();
  double time = 0.0;
};

// Keeps the points with min_range ≤ |p| ≤ max_range (and finite), in their order.
std::vector<TimedPoint> RangeGate(const std::vector<TimedPoint>& points, double min_range,
                                  double max_range);

// One point per cubic voxel of the given size: the first one met, so the output keeps the input
// order and every kept point is a real return with its own time (an average would mix times).
// Hash based (open addressing on packed 21-bit voxel coordinates), O(n).
std::vector<TimedPoint> VoxelGridSubsample(const std::vector<TimedPoint>& points,
                                           double voxel_size);

// One keypoint per cubic voxel of keypoint_voxel_size (VoxelGridSubsample), and beyond
// max_keypoints (0 = no cap) an evenly spaced subset in the input order (index i·n/cap, so a
// sweep in time order stays covered over its span).
std::vector<TimedPoint> KeypointsOf(const std::vector<TimedPoint>& preprocessed,
                                    double keypoint_voxel_size, int max_keypoints);

// Indices of the points (any frame) with min_range ≤ |p| ≤ max_range that are the first of their
// voxel: the range gate and VoxelGridSubsample in one pass over a raw sweep, without copying it.
// With threads > 1 the sweep is split into that many chunks processed in parallel and merged in
// order (same indices).
std::vector<size_t> RangeGatedVoxelIndices(const std::vector<Vec3>& points, double voxel_size,
                                           double min_range, double max_range, int threads = 1);
// The same into *out (cleared; its capacity is reused from sweep to sweep).
void RangeGatedVoxelIndices(const std::vector<Vec3>& points, double voxel_size, double min_range,
                            double max_range, int threads, std::vector<size_t>* out);

// PCA of the neighbours; false for fewer than three points or a degenerate (zero-spread) set.
bool FitPlane(const std::vector<VoxelMap::Neighbour>& neighbours, PlaneFit* plane);

// Associates map-frame points with planes of a voxel map. Holds its neighbour buffer, so use
// one per thread.
class PlaneAssociator {
 public:
  PlaneAssociator(const VoxelMap& map, const LidarFrontendOptions& options);

  // For q (robot frame) observed at p_map = T_mr q: a PCA plane and |nᵀ(p_map − centroid)| ≤
  // max_plane_distance. association "knn": the plane of ≥ min_neighbours of ≤ max_neighbours
  // nearest map points (±1 voxel), through their centroid (less noisy than the nearest point
  // alone); "voxel_plane": the plane kept by the map for p_map's voxel when it holds ≥
  // min_neighbours points and is at most voxel_plane_max_thickness thick, else the kNN plane. Fills
  // *association (weight = the planarity weight) and returns true on success. Reads the map only:
  // one associator per thread. *thickness (when given): the plane's σ3, the RMS distance of the
  // points it was fitted to from it.
  bool Associate(const Vec3& q_robot, const Vec3& p_map, PlaneAssociation* association,
                 double* thickness = nullptr);

 private:
  // The plane of the map points around p_map across the line its k nearest neighbours
  // (neighbours_) form (LidarFrontendOptions::line_neighbourhood_ratio); false when they are a
  // line too. *plane on entry: the kNN fit of neighbours_ (its normal and middle axis span the
  // directions across the line); replaced by the wider fit on success.
  bool FitAcrossLine(const Vec3& p_map, PlaneFit* plane);

  const VoxelMap& map_;
  LidarFrontendOptions options_;
  bool voxel_planes_;
  std::vector<VoxelMap::Neighbour> neighbours_;
  std::vector<VoxelMap::Neighbour> wide_, probe_;  // FitAcrossLine's buffers
};

// A preprocessed sweep as positions in the raw (lidar-frame) sweep, in sweep order.
struct SweepSelection {
  std::vector<size_t> indices;     // raw indices of the preprocessed points
  std::vector<Vec3> points_robot;  // T_robot_lidar · raw point, per entry of indices
  std::vector<size_t> keypoints;   // entries of indices that are keypoints, increasing
};

// Per-sweep preprocessing with the scan counter of the SPEC (finer subsampling for the first
// scans), and the voxel-map options of the front-end options.
class LidarFrontend {
 public:
  explicit LidarFrontend(const LidarFrontendOptions& options);

  // Range gate + subsampling (voxel_size, or initial_voxel_size for the first initial_scans
  // sweeps). Advances the scan counter.
  std::vector<TimedPoint> Preprocess(const std::vector<TimedPoint>& sweep);
  // Preprocess and Keypoints of a raw lidar-frame sweep without copying it: the range gate and
  // subsampling in the lidar frame (RangeGatedVoxelIndices, options' threads), then, streamed over
  // its survivors in order, the same in the robot frame (T_robot_lidar · p) and the keypoint
  // voxels. The same points and keypoints as Keypoints(Preprocess(T_robot_lidar · survivors)):
  // each stage keeps the first point of a voxel among the previous stage's survivors in their
  // order, which a stream of filters computes alike. With an identity extrinsic the robot-frame
  // stage is skipped: it would keep every survivor (same points, gate and voxels, one point per
  // voxel already). Advances the scan counter.
  // `threads` (>= 1) for the range gate and subsampling; 0 = LidarFrontendOptions::threads. The
  // selection is the same for any count.
  void SelectSweep(const std::vector<Vec3>& sweep_lidar, const SE3& T_robot_lidar,
                   SweepSelection* selection, int threads = 0);
  // The voxel size the next Preprocess call will use.
  double NextVoxelSize() const;
  // One keypoint per keypoint_voxel_size voxel of a preprocessed sweep.
  std::vector<TimedPoint> Keypoints(const std::vector<TimedPoint>& preprocessed) const;

  // Inserts map-frame points and drops the voxels farther than max_map_distance from the robot
  // position (checked whenever the robot has moved 5% of that distance since the last check).
  void UpdateMap(const std::vector<Vec3>& points_map, const Vec3& robot_position_map);

  const VoxelMap& map() const { return map_; }
  VoxelMap& map() { return map_; }
  const LidarFrontendOptions& options() const { return options_; }
  int num_scans() const { return num_scans_; }

  static VoxelMap::Options MapOptions(const LidarFrontendOptions& options);

 private:
  LidarFrontendOptions options_;
  VoxelMap map_;
  int num_scans_ = 0;
  Vec3 last_removal_position_ = Vec3::Zero();
  bool removal_done_ = false;
};

}  // namespace ctlio::lio
