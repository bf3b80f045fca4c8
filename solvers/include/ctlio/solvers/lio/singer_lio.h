// Singer-LIO (the paper's method, SPEC §2–§4): continuous-time lidar-inertial odometry with one
// GP knot {T_rm, ϖ, ϖ̇, b} per scan end, the SE(3) Singer prior between knots, one interpolated
// point-to-plane residual per keypoint at its own time (re-associated every round), the gyro
// and accelerometer as measurements of the interpolated state at every IMU time (biases
// interpolated linearly between knots, gravity C_mi from the initialisation), and a bias random
// walk between knots. The `lidar_gyro` method drops the accelerometer; `lidar_only` drops the
// IMU and the biases altogether.
#pragma once

#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <deque>
#include <memory>
#include <vector>

#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio {

class SingerLio final : public LioOdometry {
 public:
  explicit SingerLio(const OdometryConfig& config);
  ~SingerLio() override;

 private:
  struct Knot {
    double t = 0.0;
    int64_t t_ns = 0;
    double pose[7] = {0, 0, 0, 0, 0, 0, 1};       // T_rm (robot ← map)
    double velocity[6] = {0, 0, 0, 0, 0, 0};      // ϖ
    double acceleration[6] = {0, 0, 0, 0, 0, 0};  // ϖ̇
    double bias[6] = {0, 0, 0, 0, 0, 0};          // [b_a; b_g]
  };

  void Initialise(const PreparedScan& scan, ScanResult* result) override;
  void Process(const PreparedScan& scan, ScanResult* result) override;
  void Slide();
  void Fill(const Knot& k, ScanResult* result) const;
  void AddKnotBlocks(Knot* k);
  void SetKnotConstant(Knot* k);
  // T_mr(τ) between knots a and b from the current estimates (GP interpolation, SPEC §2).
  SE3 PoseAt(const Knot& a, const Knot& b, double tau) const;

  ceres::Problem problem_;
  PoseManifold pose_manifold_;
  RotationManifold rotation_manifold_;
  std::unique_ptr<ceres::LossFunction> lidar_loss_;
  std::unique_ptr<ceres::LossFunction> accel_loss_;
  double C_mi_block_[4] = {0, 0, 0, 1};      // gravity rotation, [qx qy qz qw]
  std::deque<std::unique_ptr<Knot>> knots_;  // oldest first; front is held constant
  struct Impl;
  std::unique_ptr<Impl> impl_;  // the GP model (kept out of the header)
};

}  // namespace ctlio::lio
