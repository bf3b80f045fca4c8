// The IMU-as-input baseline (SPEC §3, §4, §6): navigation states {T_wb, v, b} at scan ends,
// one preintegrated IMU factor (Forster et al. 2017) between consecutive states, the lidar
// points deskewed by integrating the IMU from the previous state (re-done after every solve),
// and point-to-plane residuals at the single pose of the scan end. Same front end and same
// window scheme as Singer-LIO (SingerLio), so that only the motion model differs.
#pragma once

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
  // A state's blocks live in the window; ids 8·n + {0 pose T_wb, 1 v (world), 3 bias}.
  struct State {
    double t = 0.0;
    int64_t t_ns = 0;
    StateId id = 0;
    double* pose = nullptr;      // T_wb = T_mr (body → world = map)
    double* velocity = nullptr;  // world frame, 3
    double* bias = nullptr;      // [b_a; b_g]
    std::vector<StateId> ids() const { return {id, id + 1, id + 3}; }
  };
  State AddState(double t, int64_t t_ns, const SE3& T_wb, const Vec3& v, const Vec6& bias);

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
  void Slide(ScanResult* result);
  void Fill(const State& s, ScanStatus status, ScanResult* result) const;

  std::deque<State> states_;  // oldest first
  int64_t next_state_ = 0;
};

}  // namespace ctlio::lio
