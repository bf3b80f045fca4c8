// Every scan's pose covariance for users (issue 43; docs/user-guide/outputs.md):
// trajectory_covariance.csv beside trajectory.tum and the covariance of the nav_msgs/Odometry
// messages of --write_bag.
//
// Convention of ScanResult::pose_covariance and of the CSV: Σ of ε = [ρ; φ] (translation first)
// in T_true = Exp(ε)·T, T the pose of trajectory.tum (T_world_lidar; the world frame is the map
// frame, so the perturbation on the left of T_map_robot is the same on T_world_lidar =
// T_map_robot·T_imu_lidar): a left perturbation, its axes those of the world frame.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "output_files.h"
#include "run_odometry.h"

namespace ctlio::lioapp {

// The 21 entries of the upper triangle of S, row by row: S00 S01 … S05 S11 … S15 … S55.
std::array<double, 21> UpperTriangle(const Mat6& S);

// DIR/trajectory_covariance.csv (registered in `files`): a header line, then one line per scan
// that has a covariance (failed scans and the first, initialising one have none): t [s] and
// UpperTriangle. The write is checked (an error names the path).
void WriteTrajectoryCovariance(const std::string& dir, const std::vector<lio::ScanResult>& scans,
                               OutputFiles* files);

// The ROS covariance of a nav_msgs/Odometry pose (row-major 6×6 over [x y z roll pitch yaw]: the
// position in the header frame and small rotations about that frame's fixed axes) from Σ of ε
// at the pose T. The rotation part is φ itself (Exp(φ)·C rotates about the fixed axes); the
// position moves by δp = ρ + φ×p, so the ROS covariance is G·Σ·Gᵀ with G = [[I, −p^], [0, I]].
std::array<double, 36> RosPoseCovariance(const Mat6& S, const SE3& T);

// The ROS covariances of the poses of run.trajectory (matched to run.scans by time; zeros where
// a scan has none: the first, or every scan without --pose_covariance).
std::vector<std::array<double, 36>> RosPoseCovariances(const RunSummary& run);

}  // namespace ctlio::lioapp
