// Trajectory evaluation (SPEC §6): timestamp association, Umeyama alignment (SE(3), or Sim(3) as
// an option), absolute trajectory error (ATE) and relative pose error (RPE) over distance and time
// windows.
//
// Conventions: poses are T_world_sensor (SPEC §1). Alignment maps the estimate's world into the
// reference's: p_ref ≈ s·C·p_est + r. ATE is the RMSE of the position differences after alignment
// (the paper's metric). RPE for a window (i, j) compares relative motions,
// E = (T_ref,i⁻¹ T_ref,j)⁻¹ (T_est,i⁻¹ T_est,j), translation error |r(E)|, rotation error |Log
// C(E)|.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio::eval {

struct Similarity {
  SE3 pose;            // C, r
  double scale = 1.0;  // s (1 for SE(3))
  Vec3 operator*(const Vec3& p) const { return scale * (pose.rotation() * p) + pose.translation(); }
};

// Least-squares s, C, r minimising Σ|target_i − (s·C·source_i + r)|² (Umeyama, PAMI 1991), with
// the reflection guard. `with_scale` = false gives SE(3). Throws on fewer than 3 points or a
// degenerate (collinear) configuration when a rotation is requested.
Similarity Umeyama(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                   bool with_scale);

// Pairs (i_est, i_ref) of nearest timestamps, |Δt| ≤ tolerance_ns, each pose used at most once,
// in time order. Both inputs must be time-sorted.
std::vector<std::pair<size_t, size_t>> Associate(const std::vector<io::StampedPose>& estimate,
                                                 const std::vector<io::StampedPose>& reference,
                                                 int64_t tolerance_ns);

enum class AlignmentMode { kNone, kSe3, kSim3 };
AlignmentMode ParseAlignmentMode(const std::string& s);  // "none" | "se3" | "sim3"

struct Statistics {
  size_t count = 0;
  double rmse = 0, mean = 0, median = 0, max = 0, min = 0;
};
Statistics Summarise(const std::vector<double>& values);

struct AteResult {
  Statistics translation;  // m
  Similarity alignment;
  std::vector<int64_t> times_ns;
  std::vector<Vec3> estimate_aligned, reference;  // positions
  std::vector<double> errors;                     // |p_ref − align(p_est)|
};

// Associated poses: estimate[k] ↔ reference[k]. Throws if sizes differ or are < 3.
AteResult ComputeAte(const std::vector<io::StampedPose>& estimate,
                     const std::vector<io::StampedPose>& reference, AlignmentMode mode);

struct RpeResult {
  std::string window;                // "10 m" or "1 s"
  Statistics translation;            // m
  Statistics rotation;               // deg
  double translation_percent = 0.0;  // distance windows: mean translation error / distance · 100
};

// Windows start at every pose i; j is the first pose with path length along the reference
// ≥ `meters` (distance) or time ≥ t_i + `seconds`. Windows that run off the end are skipped.
RpeResult ComputeRpeDistance(const std::vector<io::StampedPose>& estimate,
                             const std::vector<io::StampedPose>& reference, double meters);
RpeResult ComputeRpeTime(const std::vector<io::StampedPose>& estimate,
                         const std::vector<io::StampedPose>& reference, double seconds);

struct Report {
  std::string estimate_path, reference_path;
  size_t estimate_poses = 0, reference_poses = 0, associated = 0;
  double tolerance_s = 0.0;
  std::string alignment;  // "se3" | "sim3" | "none"
  AteResult ate;
  std::vector<RpeResult> rpe;
};
std::string ReportText(const Report& r);
std::string ReportJson(const Report& r);

}  // namespace ctlio::eval
