// The IMU-as-input baseline (SPEC §3, §4, §6): navigation states {T_wb, v, b} at scan ends,
// one preintegrated IMU factor (Forster et al. 2017) between consecutive states, the lidar
// points deskewed by integrating the IMU from the previous state (re-done after every solve),
// and point-to-plane residuals at the single pose of the scan end. Same front end and same
// window scheme as Singer-LIO (SingerLio), so that only the motion model differs.
#pragma once

#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <deque>
#include <memory>
#include <vector>

#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio {

class ImuInputLio final : public LioOdometry {
 public:
  explicit ImuInputLio(const OdometryConfig& config);
  ~ImuInputLio() override;

 private:
  struct State {
    double t = 0.0;
    int64_t t_ns = 0;
    double pose[7] = {0, 0, 0, 0, 0, 0, 1};  // T_wb = T_mr (body → world = map)
    double velocity[3] = {0, 0, 0};          // world frame
    double bias[6] = {0, 0, 0, 0, 0, 0};     // [b_a; b_g]
  };

  void Initialise(const PreparedScan& scan, ScanResult* result) override;
  void Process(const PreparedScan& scan, ScanResult* result) override;

  // Poses T_wb at the boundaries of the IMU segments over [from.t, t_end], integrated from the
  // current estimate of `from` (pose, velocity, bias).
  struct DeskewTable {
    std::vector<double> t;
    std::vector<SE3> T_wb;
    SE3 Interpolate(double tau) const;
  };
  DeskewTable Integrate(const State& from, double t_end) const;
  void Slide();
  void Fill(const State& s, ScanStatus status, ScanResult* result) const;

  ceres::Problem problem_;
  PoseManifold pose_manifold_;
  std::unique_ptr<ceres::LossFunction> lidar_loss_;
  std::deque<std::unique_ptr<State>> states_;  // oldest first; front is held constant
};

}  // namespace ctlio::lio
