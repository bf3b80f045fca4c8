// Singer-LIO (the paper's method, SPEC §2–§4): continuous-time lidar-inertial odometry with one
// GP knot {T_rm, ϖ, ϖ̇, b} per scan end, the SE(3) Singer prior between knots, one interpolated
// point-to-plane residual per keypoint at its own time (re-associated every round), the gyro
// and accelerometer as measurements of the interpolated state at every IMU time (biases
// interpolated linearly between knots, gravity C_mi from the initialisation), and a bias random
// walk between knots. The `lidar_gyro` method drops the accelerometer; `lidar_only` drops the
// IMU and the biases altogether.
//
// Window (SPEC §4, §5): the window_knots newest knots are free; before a new knot is added the
// oldest is marginalised by Schur complement (SlidingWindow::Marginalize) into one prior on the
// knot that stays, so its lidar, IMU and GP information is kept, not dropped.
#pragma once

#include <deque>
#include <memory>
#include <vector>

#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lio {

class SingerLio final : public LioOdometry {
 public:
  explicit SingerLio(const OdometryConfig& config);
  ~SingerLio() override;

 private:
  // A knot's blocks live in the window (SlidingWindow owns the storage); state ids are
  // 8·n + {0 pose T_rm, 1 ϖ, 2 ϖ̇, 3 bias [b_a; b_g]} for the n-th knot.
  struct Knot {
    double t = 0.0;
    int64_t t_ns = 0;
    StateId id = 0;  // 8·n
    double* pose = nullptr;
    double* velocity = nullptr;
    double* acceleration = nullptr;
    double* bias = nullptr;  // nullptr for lidar_only
    std::vector<StateId> ids() const;
  };

  void Initialise(const PreparedScan& scan, ScanResult* result) override;
  void Process(const PreparedScan& scan, ScanResult* result) override;
  // Marginalises the oldest knots until window_knots − 1 remain (before a new knot is added).
  void Slide(ScanResult* result);
  void Fill(const Knot& k, ScanResult* result) const;
  Knot AddKnot(double t, int64_t t_ns, const SE3& T_rm, const Vec6& w, const Vec6& dw,
               const Vec6& bias);
  // T_mr(τ) between knots a and b from the current estimates (GP interpolation, SPEC §2).
  SE3 PoseAt(const Knot& a, const Knot& b, double tau) const;

  static constexpr StateId kGravityId = -1;  // C_mi, [qx qy qz qw]
  double* C_mi_block_ = nullptr;
  std::deque<Knot> knots_;  // oldest first
  int64_t next_knot_ = 0;
  struct Impl;
  std::unique_ptr<Impl> impl_;  // the GP model (kept out of the header)
};

}  // namespace ctlio::lio
