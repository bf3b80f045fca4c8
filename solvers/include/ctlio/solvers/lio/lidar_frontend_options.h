// Parameters of the lidar front end (SPEC §4), with the defaults of CT-ICP / the reference
// implementation. data/lidar_frontend.yaml documents every key; LoadLidarFrontendOptions reads
// it. Units: metres, seconds.
#pragma once

#include <string>

namespace YAML {
class Node;
}

namespace ctlio::lio {

struct LidarFrontendOptions {
  // Range gate: points closer than min_range (the robot itself) or farther than max_range are
  // dropped before anything else.
  double min_range = 1.0;
  double max_range = 100.0;

  // Voxel-grid subsampling of each sweep (one point per voxel); finer for the first scans while
  // the map is still sparse.
  double voxel_size = 0.5;
  double initial_voxel_size = 0.2;
  int initial_scans = 20;

  // Keypoints: one per keypoint_voxel_size voxel of the subsampled sweep.
  double keypoint_voxel_size = 1.0;
  // At most this many keypoints per sweep (0 = no cap): beyond it, an evenly spaced subset (in
  // firing order, so the sweep's time span stays covered). Bounds the per-scan cost in large,
  // open scenes (KISS-ICP style): a 100 m room at 1 m keypoint voxels gives ~20 000 keypoints.
  int max_keypoints = 0;

  // Voxel hash map.
  double map_voxel_size = 1.0;
  int max_points_per_voxel = 20;
  double min_point_distance = 0.1;  // minimum spacing of the points in one voxel
  double max_map_distance = 400.0;  // voxels farther than this from the robot are removed

  // Association: k nearest neighbours from the ±1 voxels, PCA plane, gate on the point-to-plane
  // distance.
  int max_neighbours = 20;
  int min_neighbours = 10;
  double max_plane_distance = 1.0;
  // "knn": the plane of the nearest map points, fitted per query; "voxel_plane": the plane the
  // map keeps per voxel (moments updated on insertion, as in iG-LIO / VoxelMap), a hash lookup,
  // with the kNN plane where the voxel holds fewer than min_neighbours points.
  std::string association = "knn";
  // A kNN neighbourhood whose spread across its main direction is below this fraction of the
  // spread along it (σ2 < line_neighbourhood_ratio · σ1) is a line, not a plane: a sparse
  // multi-beam lidar's map seen from one place holds rings (a beam's cut through a surface), 1–2 m
  // apart on the floor of a VLP-16, so the nearest points of a ring point are that ring, whose
  // fitted normal is any direction across it and whose planarity weight is ≈ 0. Then the plane is
  // fitted again to the points around it — the kNN of probes one map voxel away on either side
  // across the line, within two map voxels of the point — which reach the neighbouring ring of
  // the same surface; a neighbourhood still a line after that gives no association. 0 = off (the
  // kNN plane as it is). docs/experiments/covariance.md, "16 beams".
  double line_neighbourhood_ratio = 0.0;
  // A kNN plane thicker than this (σ3, the RMS distance of its neighbours from it) is no plane:
  // foliage (returns scattered through a crown's depth, from where each beam enters, which moves
  // with the viewpoint) or a convex surface (a trunk, a pole, whose fitted plane is a chord that
  // the surface's own points lie outside of by ~a²/4R for a patch of radius a). Planarity weights
  // keep such patches near a wall's weight. 0 = off; measured, not shipped
  // (docs/experiments/scoreboard.md, "Foliage and convex surfaces").
  double max_plane_thickness = 0.0;  // m
  // The plane's own scatter in the residual's σ: a keypoint's σ² gains (plane_thickness_noise ·
  // σ3)², σ3 the thickness of the plane it is associated with, so a point on foliage or a convex
  // patch weighs less than one on a wall, and none is dropped (the gate above drops them, which
  // leaves a stretch seeing mostly hedges and crowns too few planes). 0 = off; 1 in five sensor
  // files, off for the VLP-16, whose yaw drifts where hedges line a street (scoreboard.md).
  double plane_thickness_noise = 0.0;
  // voxel_plane only: a voxel's plane is used when its thickness σ3 (the smallest standard
  // deviation of its points) is at most this, else the kNN plane (a voxel across an edge or a
  // corner is no plane, while the nearest points on one face are).
  double voxel_plane_max_thickness = 0.05;  // m

  // Threads of the front end (association of the keypoints, range gate + subsampling of the raw
  // sweep); results equal one thread's. Independent of the solver's window.threads.
  int threads = 1;

  // Registration: re-association rounds, solver iterations per round, robust loss.
  int max_iterations = 10;
  int solver_iterations = 5;
  // The budget of a scan whose interval no IMU sample measures (lidar_only always; an IMU outage
  // for Singer-LIO and lidar_gyro, imu_residuals == 0; not the IMU-as-input baseline, whose gap
  // mode is its own, lio_odometry.h): the lidar alone moves the pose from the motion
  // prior's prediction, which without the IMU can be degrees off (docs/experiments/imu-dropout.md),
  // so a budget tuned for an IMU-predicted start (2 rounds × 3) stops mid-way and the error grows
  // scan by scan (tuning index 101, hdl32e quad walk, 2 s outage: 29 m; 0.03 m with 10 × 5).
  // Rounds still end at convergence. 0: max_iterations / solver_iterations. Scans with IMU
  // samples keep the budget above, so runs without an outage are unchanged bit for bit.
  int max_iterations_without_imu = 10;
  int solver_iterations_without_imu = 5;
  // The largest translation [m] the lidar may move such a scan's pose away from the prediction
  // before its registration is rejected (ScanWithoutImu::RejectsCorrection; 0 = off): the lidar
  // residuals leave the window, the states keep the prediction and the scan is reported degenerate
  // with its map points left out. In an IMU outage the prediction extrapolates the motion of the
  // last second over one sweep, and in runs that hold the lidar moves it 0.07 m (median) and at
  // most 0.46 m on the spinning sensors (tuning runs of the dropout table), while a registration
  // that slid along a weak direction moved it 0.61 m and the next sweeps lost their associations
  // (pandar_xt32 quad walk 4, 2 s outage: 32 failed scans; docs/experiments/imu-dropout.md, which
  // also has the limit's cost on an unseen run). Applies to Singer-LIO and lidar_gyro in an
  // outage, not to lidar_only, whose every scan has no IMU.
  double max_correction_without_imu = 0.0;  // m
  // The same for the rotation [rad] of the pose away from the prediction (0 = off): a
  // registration can turn an outage scan onto a wrong minimum while moving it less than the
  // translation limit (pandar_xt32 box medium 4, 2 s outage: 17° in one scan at 0.2 m, the run
  // 62° off; docs/experiments/imu-dropout.md, "Rejecting a registration that turns").
  double max_rotation_correction_without_imu = 0.0;  // rad
  // The budget of a scan predicted at high speed (registration_budget.h): a scan whose predicted
  // mean speed over its interval is at least high_speed [m/s] gets max_iterations_high_speed ×
  // solver_iterations_high_speed (0 = max_iterations / solver_iterations). At 12–14 m/s the
  // IMU-as-input baseline's 4 rounds × 3 stop short and its rotation drifts from ~13 s of a 20 s
  // drive (os1_64 town 0: 5.15 m ATE; 10 × 5: 7.2 cm), while the same budget on walking and
  // handheld-fast sweeps (≤ 3 m/s) costs accuracy (docs/experiments/scoreboard.md, "The
  // baseline's budget in 20 s drives"). 0 = off: every scan below it keeps the budget above,
  // bit for bit. A scan without IMU samples keeps its own budget.
  double high_speed = 0.0;  // m/s
  int max_iterations_high_speed = 0;
  int solver_iterations_high_speed = 0;
  // Standard deviation of a point-to-plane residual (range noise of an OS1-64 class lidar plus
  // plane-fit noise): residuals enter the problem as w/σ · nᵀ(p_ref − T_mr q), which sets their
  // weight against the GP prior (whitened by Q⁻¹, SPEC §2).
  double point_noise_sigma = 0.03;  // m
  // An angular part of a keypoint's σ (0 = off: point_noise_sigma for every keypoint):
  //   σ_i² = point_noise_sigma² + (point_noise_angle · |q_i|)²,
  // |q_i| the keypoint's distance from the robot frame's origin (the lidar is within centimetres of
  // it). Errors that grow with range — a rotation error of the deskewing or of the map's plane fit,
  // a plane fitted to the sparse map far away, a beam's angle — are absent from a constant σ, which
  // then weighs the far keypoints of an open scene (a park's trees at 10–40 m) as much as a room's
  // walls at 2–5 m: one σ had to serve both (docs/experiments/scoreboard.md, cause W). The robust
  // loss acts on the whitened residual (its scale stays loss_scale / point_noise_sigma).
  double point_noise_angle = 0.0;  // rad
  std::string loss = "cauchy";     // "cauchy", "huber" or "none"
  double loss_scale = 0.1;  // metres, on the planarity-weighted residual w·nᵀ(p_ref − T_mr q)
  // Residual blocks of the continuous-time point-to-plane residuals (Singer-LIO, lidar_gyro,
  // lidar_only; with the extrinsic estimated and in the IMU-as-input baseline always "point"):
  // "point": one Ceres residual block per keypoint with the loss as Ceres applies it;
  // "interval": the keypoints of one knot interval as one block (ContinuousPointToPlaneBatch),
  // still one residual and one robust loss per keypoint, applied inside the block as Ceres
  // applies it to a one-point block: the same estimates up to rounding at a fraction of Ceres'
  // per-block cost (docs/experiments/latency.md);
  // "square_root": that block handed to Ceres in square-root form, W + 1 = 37 rows with the same
  // cost, gradient and Gauss–Newton Hessian (ContinuousPointToPlaneBatch::Form::kSquareRoot):
  // the same estimates up to rounding, without Ceres' serial per-row work
  // (docs/experiments/latency.md).
  std::string residual_blocks = "square_root";
  // Stop re-associating when the knots' poses move less than this between rounds.
  double convergence_translation = 1e-3;  // m
  double convergence_rotation = 1e-4;     // rad
  // A keypoint that moved less than this in the map (at the current estimate) since the round
  // that searched its plane keeps that plane in the next round instead of searching again (the
  // kNN search and the plane fit are most of the association's cost, and a small move seldom
  // changes the neighbours). 0 = search every round.
  double reassociation_distance = 0.0;  // m

  // Throws std::invalid_argument naming the first bad field.
  void Validate() const;
};

// Reads the options from a YAML mapping; keys not present keep their value in `base` (the
// defaults unless given); unknown keys and ill-typed values throw std::runtime_error naming
// `source` and the line.
LidarFrontendOptions LidarFrontendOptionsFromYaml(const YAML::Node& node,
                                                  const std::string& source = "<yaml>",
                                                  const LidarFrontendOptions& base = {});
LidarFrontendOptions LoadLidarFrontendOptions(const std::string& path);

}  // namespace ctlio::lio
