// Accelerometer relabelling check against a reference that does not use the accelerometer
// (docs/user-guide/bad-input.md, "Accelerometer axes against a lidar + gyro reference").
//
// The frame check (frame_consistency.h) judges the accelerometer against the lidar trajectory of
// the method that fused it: where the lidar gives way, that trajectory follows a swapped or
// flipped accelerometer part of the way and the residual stays at 0.04–0.15 m/s², the level of
// clean runs in shaky walks. Here the same fit runs on the poses of a second estimator, lidar_gyro
// (the lidar and the gyro, no accelerometer term), over the first scans of the run: its positions
// cannot bend towards the accelerometer, so a relabelled accelerometer is explained by its
// relabelling P (one of the 47 signed permutations ≠ I, no free parameter) about as well as by a
// free 3×3 map, and clearly better than by the identity. Warned when
//   rms(I) ≥ min_gain · rms(P*)   and   rms(P*) ≤ max_over_free · rms(M free),
// the second condition keeping out clean runs whose reference trajectory is poor in a way no
// relabelling describes (a free map absorbs any linear error; a relabelling only the defect).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/frame_consistency.h"

namespace ctlio::lioapp {

struct RelabellingOptions {
  // Measured over 80-scan references (8 s; docs/user-guide/bad-input.md): clean runs, tuning
  // index 100 and unseen 320/310 in the box, office, quad and town with five sensors, gain
  // rms(I)/rms(P*) 0.10–1.01 (2.17 once, a slow box run whose reference the free map fits 17x
  // better than any relabelling); swapped or flipped accelerometers in the box 3.4–41, with
  // rms(P*)/rms(free) 1.05–1.18 (clean runs with a gain near 1: 1.02–1.54).
  double min_gain = 1.5;
  double max_over_free = 1.5;
};

// The warning for a reference fit (empty when not judged or no relabelling stands out):
// "accelerometer axes look swapped/flipped: best relabelling true (x, y, z) = reading (...) …".
std::string RelabellingWarning(const FrameConsistency& reference, int scans,
                               const RelabellingOptions& options = {});

class AccelReference {
 public:
  // `config`: the run's config (extrinsic, gravity and IMUs as the run uses them); the reference
  // runs it as lidar_gyro without online calibration over the first `max_scans` scans.
  AccelReference(const lio::OdometryConfig& config, size_t max_scans);
  ~AccelReference();
  bool Active() const { return scans_ < max_scans_; }
  void AddImu(const lio::ImuSample& sample);
  void AddScan(const lio::LidarScan& scan);
  int scans() const { return static_cast<int>(scans_); }
  FrameConsistency Result() const { return frames_.Result(); }

 private:
  std::unique_ptr<lio::LioOdometry> odometry_;
  FrameConsistencyCheck frames_;
  size_t max_scans_;
  size_t scans_ = 0;
};

}  // namespace ctlio::lioapp
