// A perturbed NOMINAL lidar–IMU extrinsic, to measure online calibration against the truth: the
// simulator moves the lidar with the true T_imu_lidar (SimConfig::imu_from_lidar) but hands out
// (dataset file, DataSource::ImuFromLidar) a nominal one that is off by a given rotation and
// translation; the truth stays available (DataSource::TrueImuFromLidar, `true_imu_from_lidar` in
// ctlio_sim.yaml). Text syntax (`--extrinsic_error` of ctlio_simulate and ctlio_experiment,
// `--sim_extrinsic_error` of ctlio_odometry):
//
//   <angle>deg[@ax:ay:az],<distance>m[@dx:dy:dz]      e.g. 3deg,0.10m   or   3deg@0:0:1,0.1m@1:0:0
//
// The nominal extrinsic is C_nom = Exp(angle·a)·C_true, p_nom = p_true + distance·d (a, d unit
// vectors in the IMU frame, normalised from the given ones). Without @, a and d are drawn
// uniformly on the sphere from std::seed_seq{seed, 0xE4711, index} — fixed per sequence, different
// between sequences. "" or "0deg,0m" = no error.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "ctlio/manifolds/se3.h"

namespace ctlio::sim {

struct ExtrinsicError {
  double rotation_deg = 0.0;
  double translation_m = 0.0;
  std::optional<Vec3> rotation_axis;          // unit; drawn when absent
  std::optional<Vec3> translation_direction;  // unit; drawn when absent
  bool IsZero() const { return rotation_deg == 0.0 && translation_m == 0.0; }
};

// Throws std::runtime_error quoting the text on malformed input (negative or non-finite
// magnitudes, a zero axis, a missing unit).
ExtrinsicError ParseExtrinsicError(const std::string& text);

// The nominal extrinsic for sequence `index` (see above).
SE3 NominalExtrinsic(const SE3& truth, const ExtrinsicError& error, uint64_t seed, int index);

// The error of an extrinsic estimate: rotation angle of C_est·C_trueᵀ [deg], and |p_est − p_true|
// [m].
struct ExtrinsicErrorSize {
  double rotation_deg = 0.0;
  double translation_m = 0.0;
};
ExtrinsicErrorSize MeasureExtrinsicError(const SE3& estimate, const SE3& truth);

// Whether the error δ = Log(T_true·T_est⁻¹) (the left perturbation [ρ; φ] that a marginal
// covariance of T_est describes) lies within k·σ on every translation / rotation axis.
struct SigmaCoverage {
  bool translation = false, rotation = false;
};
SigmaCoverage CoveredBySigma(const SE3& estimate, const SE3& truth, const Vec6& sigma,
                             double k = 3.0);

}  // namespace ctlio::sim
