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
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/frame_consistency.h"

namespace ctlio::lioapp {

// The frame check of IMU 0 as the estimator sees it: its configured pose and clock offset (the
// samples placed at t + δ, as the estimator places them). Every check of a run's IMU frame is
// made here, so none judges the raw stamps of a configured offset.
FrameConsistencyCheck ImuFrameCheck(const lio::OdometryConfig& config);

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

// The method's positions against the reference's over the scans both registered, each trajectory
// taken relative to its first common pose (T0⁻¹·T, so the map frames need not agree):
//   rms_m = sqrt(mean |p_method − p_reference|²),  max_m = max |…|,
//   path_m = Σ |p_reference(k) − p_reference(k−1)|  (the reference's distance travelled),
//   estimate_path_m the same for the method's positions; extent_m / estimate_extent_m the
//   largest distance from the first common position of the reference / the method.
// A general statistic: any IMU defect that bends the fused trajectory away from what the lidar and
// the gyro alone say (axes, units, extrinsic) shows, whether or not a relabelling explains it.
struct ReferenceDisagreement {
  int pairs = 0;
  double rms_m = 0.0;
  double max_m = 0.0;
  double path_m = 0.0;
  double estimate_path_m = 0.0;
  double extent_m = 0.0;
  double estimate_extent_m = 0.0;
};

// Whether the reference itself ran off: lidar + gyro alone, without the accelerometer's hold, can
// lose its way where the lidar is sparse, and then both of its verdicts (relabelling, departure)
// are about the reference, not the IMU. A method that follows a defective accelerometer goes
// further than the reference; a reference that ran off goes further than the method. Judged by
// the extent (farthest distance from the start), not the path, which a jittery but sound
// reference lengthens. max_extent_ratio: see accel_reference_test.cc for the measured values.
struct ReferenceTrustOptions {
  double max_extent_ratio = 1.5;
  double min_extent_m = 1.0;  // below it (hardly moved) not judged
};
// "" when the reference is trusted (or not enough to judge), else the note written instead of
// the verdicts.
std::string ReferenceRanOff(const ReferenceDisagreement& d,
                            const ReferenceTrustOptions& options = {});

struct DisagreementOptions {
  // rms_m / path_m above this warns; 0 = never. Measured over 80-scan references (8 s;
  // docs/user-guide/bad-input.md, "Departure from the reference"): 66 clean runs 0.09-7.2 % (the
  // 7.2 % a baseline run whose estimate was itself 3.5 m off; 3.58 % at most with a good one), the
  // baseline following a flipped accelerometer 24-194 % (Mid-360 quad fast, the box).
  double max_fraction = 0.15;
  double min_path_m = 1.0;  // below it the fraction is noise: not judged
  int min_pairs = 20;
};

// "the estimate departs from a lidar + gyro reference by …" or empty when within the threshold.
std::string DisagreementWarning(const ReferenceDisagreement& d, int scans,
                                const DisagreementOptions& options = {});

class AccelReference {
 public:
  // `config`: the run's config (extrinsic, gravity and IMUs as the run uses them); the reference
  // runs it as lidar_gyro without online calibration over the first `max_scans` scans.
  AccelReference(const lio::OdometryConfig& config, size_t max_scans);
  ~AccelReference();
  bool Active() const { return scans_ < max_scans_; }
  void AddImu(const lio::ImuSample& sample);
  void AddScan(const lio::LidarScan& scan);
  // The method's pose for the scan just handed to AddScan (only read, never fed back).
  void AddEstimate(int64_t t_ns, const SE3& T_mr);
  int scans() const { return static_cast<int>(scans_); }
  FrameConsistency Result() const { return frames_.Result(); }
  ReferenceDisagreement Disagreement() const;

 private:
  std::unique_ptr<lio::LioOdometry> odometry_;
  FrameConsistencyCheck frames_;
  size_t max_scans_;
  size_t scans_ = 0;
  bool took_last_scan_ = false;
  std::vector<std::pair<int64_t, SE3>> reference_poses_, estimate_poses_;
};

}  // namespace ctlio::lioapp
