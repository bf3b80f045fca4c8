// A pose covariance whose noise levels follow the data (window.pose_covariance_adaptive, issue 43):
// the estimate keeps its configured σ (they weigh lidar, IMU and motion prior as the estimate
// needs), while the covariance scales each group's information by the variance its own residuals
// show. docs/experiments/covariance.md, "Adaptive noise levels".
//
// Variance-component estimation (Helmert; Förstner 1979): for a group g of whitened residuals
// r_g with information H_g in the window's total H = Σ_g H_g/s_g, the unbiased variance factor is
//   ŝ_g = r_gᵀr_g / (n_g − tr(H⁻¹·H_g/s_g)),                                           (1)
// n_g − tr(…) being the group's share of the redundancy (what the fit did not absorb). For the
// lidar group a robust form: ŝ_l = n_eff·σ_eff²/σ², σ_eff² the robust spread of its
// point-to-plane residuals (LidarSpread; the inliers', redundancy ≈ n_l: hundreds of residuals
// against ≤ 30 states) and n_eff an effective-sample-size inflation for the errors the residuals
// share and the pose absorbs (the map's, the deskewing's), which no spread of residuals shows.
// The window's marginal prior holds earlier scans' information at the configured σ; it is scaled
// by s_p, the factor by which the groups' rescaling changed the newest pose's covariance,
//   s_p ← (1/6)·tr(Σ₁⁻¹·Σ_s),                                                             (2)
// Σ₁ with every factor 1, Σ_s with the current ones (a fixed point: with one common factor s for
// every group, (2) returns s, and the prior is the old information rescaled exactly). All factors
// are smoothed over scans (exponential, in log space) and clamped to [min_scale, max_scale].
#pragma once

#include <ceres/problem.h>

#include <optional>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

// (1.4826·median|r_i|)² of the whitened residuals of `blocks` (no loss applied): the robust
// variance factor of a group with outliers. 1 without residuals or if the evaluation fails.
double RobustResidualVariance(ceres::Problem* problem,
                              const std::vector<ceres::ResidualBlockId>& blocks);

// Σ r² (no loss) and the residual count of `blocks`. χ² NaN if the evaluation fails.
struct GroupChiSquare {
  double chi2 = 0.0;
  int n = 0;
};
GroupChiSquare EvaluateGroupChiSquare(ceres::Problem* problem,
                                      const std::vector<ceres::ResidualBlockId>& blocks);

// The spread of one scan's point-to-plane residuals e_i [m] (at the estimate), grouped by the
// cell (edge `cell` [m]) of their plane's reference point: residuals on one map plane share its
// error, e_i = c_j + ν_i (ν_i independent, variance σ_p²; c_j the plane's, σ_c²). Then the
// group means m_j have variance σ_c² + σ_p²/n_j, and a residual of a group of n_j carries the
// information of one with variance σ_p² + n_j·σ_c² along its plane's normal (the compound-
// symmetric covariance σ_p²I + σ_c²11ᵀ on the group mean, the effective-sample-size argument).
// Robust estimates: σ_p² from the MAD of the deviations from the group means (groups ≥ 2),
// σ_c² = max(0, var_MAD(m_j) − σ_p²·mean(1/n_j)).
struct LidarSpread {
  double point_variance = 0.0;   // σ_p² [m²]
  double common_variance = 0.0;  // σ_c² [m²]
  double mean_group_size = 1.0;  // n̄ = Σn_j²/Σn_j, the group size a residual sees
  int residuals = 0;
  int groups = 0;
  // σ_p² + n̄·σ_c²: one residual's variance with its group's shared error spread over it.
  double effective_variance() const { return point_variance + mean_group_size * common_variance; }
};
// The cell of MeasureLidarSpread in the odometry: the map voxels' scale. At 1 m a scan's ~600
// keypoints of the simulated box fall in ~595 cells (their planes are local fits), so the shared
// error that matters — of whole walls, absorbed by the pose — is not in the spread; hence the
// inflation window.pose_covariance_lidar_neff (docs/experiments/covariance.md).
inline constexpr double kLidarPlaneCell = 1.0;

LidarSpread MeasureLidarSpread(const std::vector<double>& residuals,
                               const std::vector<Vec3>& plane_points, double cell);

// The lidar term's variance in the adaptive covariance, as the multiple of each residual's own
// configured variance that its blocks are divided by: the residuals e_i [m] whitened by the σ_i
// the window whitened them with (PointNoiseSigma: point noise, range-grown angle, plane
// thickness), their spread's effective variance (MeasureLidarSpread, cell kLidarPlaneCell) times
// n_eff. Whitening each residual by its own σ_i, not one nominal σ, keeps residuals the window
// already weighs less (far points, thick planes) from inflating every residual's variance.
double LidarVarianceFactor(const std::vector<double>& residuals, const std::vector<double>& sigmas,
                           const std::vector<Vec3>& plane_points, double neff);

// One group of residual blocks whose information the covariance divides by `scale`.
struct ScaledGroup {
  std::vector<ceres::ResidualBlockId> blocks;
  double scale = 1.0;
};

struct GroupScaledCovariance {
  Mat6 scaled;                      // Σ_s of ε (PoseCovariance's convention) with the scales
  Mat6 unscaled;                    // Σ₁: every group and the prior at scale 1
  std::vector<double> trace_share;  // tr(H_s⁻¹·H_g/s_g) per group, its absorbed residuals
};

// The newest pose's covariance from the window's dense information (SlidingWindow::Linearize)
// with each group's information divided by its scale and `prior`'s (may be null) by
// `prior_scale`; the other blocks at scale 1. Mapped to ε as PoseCovariance does. Empty if
// either information is not positive definite.
std::optional<GroupScaledCovariance> GroupScaledPoseCovariance(
    const SlidingWindow& window, StateId pose, const std::vector<ScaledGroup>& groups,
    ceres::ResidualBlockId prior, double prior_scale, const SE3& T_mr,
    const Mat6& tangent_from_body);

// The factors of (1) and (2) over a run, updated once per scan.
class AdaptiveNoiseScales {
 public:
  struct Options {
    double smoothing = 0.2;  // weight of the newest scan's estimate (log space)
    double min_scale = 1e-3;
    double max_scale = 1e3;
  };
  AdaptiveNoiseScales() = default;
  explicit AdaptiveNoiseScales(const Options& options) : options_(options) {}

  // The pose covariance with the current factors (lidar robust, the IMU groups by (1), the prior
  // by (2)), then the factors updated from this scan. `accel`/`gyro` may be empty (the
  // baseline's preintegrated factor goes in `accel`). Empty if the information is singular.
  // `lidar_estimate`: this scan's lidar variance factor (e.g. LidarSpread's effective variance
  // over point_noise_sigma²); NaN: the robust variance of the lidar blocks' own residuals.
  std::optional<Mat6> Compute(SlidingWindow* window, StateId pose, double lidar_estimate,
                              const std::vector<ceres::ResidualBlockId>& lidar,
                              const std::vector<ceres::ResidualBlockId>& accel,
                              const std::vector<ceres::ResidualBlockId>& gyro,
                              ceres::ResidualBlockId prior, const SE3& T_mr,
                              const Mat6& tangent_from_body);

  double lidar() const { return lidar_; }
  double accel() const { return accel_; }
  double gyro() const { return gyro_; }
  double prior() const { return prior_; }

 private:
  // The smoothed update of one factor; the first estimate is taken as it is.
  double Smooth(double current, double estimate, bool first) const;

  Options options_;
  bool first_ = true;
  double lidar_ = 1.0, accel_ = 1.0, gyro_ = 1.0, prior_ = 1.0;
};

}  // namespace ctlio::lio
