// Degeneracy of a scan's lidar term (docs/experiments/worlds-and-degeneracy.md): which directions
// of the scan's pose the point-to-plane residuals do not constrain (a corridor's axis, the
// horizontal plane of an open field), and how much the rest of the window (motion prior, IMU,
// marginal prior) knows along them.
//
// Lidar information. H = Σ JᵀJ of the scan's point-to-plane residuals (whitened by
// point_noise_sigma, the robust loss applied as Ceres applies it: SlidingWindow::Linearize), on
// the tangent of the newest pose with every other state held (the conditional information),
// moved into the body frame: δ_state = A·δ_body, H_body = AᵀHA (A = −I for the GP knots' T_rm,
// Ad(T_wb) for the baseline's T_wb; SPEC §1 left perturbations). Translation [m] and rotation
// [rad] have different units, so they are analysed separately, each with the other free (the
// Schur complement, so that a direction only constrained together with a rotation is not
// mistaken for a constrained one):
//   S_t = H_tt − H_tr H_rr⁺ H_rt,   S_r = H_rr − H_rt H_tt⁺ H_tr,
// and each block's eigenvalues are normalised by the block's mean eigenvalue, ν_i = 3λ_i/tr(S)
// (0 … 3; 1 on every axis for a perfectly isotropic scene such as the box room), which makes the
// test independent of the number of keypoints, the noise σ and the range. An eigenvector with
// ν_i < threshold (degeneracy.translation_threshold / rotation_threshold) is a degenerate
// direction (Zhang, Kaess & Singh, "On degeneracy of optimization-based state estimation
// problems", ICRA 2016, threshold the eigenvalues of JᵀJ; the normalisation is ours).
//
// Who carries a degenerate direction u. The prior information along u is uᵀ H_prior u, H_prior
// the marginal information of every other factor of the window (all non-lidar residuals, all
// non-constant states, Schur complement onto the newest pose, body frame); the lidar's is
// uᵀ H u. Both are whitened information [1/m², 1/rad²]; their ratio says which one holds the
// pose there.
//
// lidar_only has no IMU to carry u: solution remapping (Zhang & Singh ICRA 2016 project every
// Gauss–Newton step onto the well-constrained subspace and keep the prediction along the
// degenerate directions). Equivalent here without touching the solver: after the registration a
// PosePrior on the newest pose, centred on its constant-velocity prediction, with information
// `remap_information` along the degenerate directions only (zero elsewhere), and one more solve;
// in the limit of a large weight the solution's component along u is the prediction's and the
// other directions are re-optimised, as with the projected steps. The scan is reported
// `degenerate`.
#pragma once

#include <string>
#include <vector>

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"
#include "ctlio/solvers/sliding_window.h"

namespace ctlio::lio {

struct DegeneracyOptions {
  bool enabled = true;  // analyse every registered scan (logged; lidar_only remaps)
  // Normalised eigenvalue ν = 3λ/tr(S) below which a direction is degenerate. Set on the
  // tuning sequences (index 100, 3 s, 16 beams; walking, street vehicle, box medium):
  // 0.05 missed the corridor axis (ν_t 0.09–0.3 while lidar_only drifted along it: the corner
  // behind the start adds a few points on the axis), 0.25 flagged half of the park and the street
  // (where lidar_only then lost 2–3 m through the remapping); 0.1 flags ~half of the corridor
  // scans. The rotation block is dominated by far points (lever arm ~ range), so the corridor's
  // roll (lever arm ≤ 1.5 m) has ν_r ≈ 0.01–0.03 although its information is 1e3 rad⁻²: 0.01.
  double translation_threshold = 0.1;
  double rotation_threshold = 0.01;
  // lidar_only: information [1/m², 1/rad²] of the remapping prior along a degenerate direction
  // (1e8: σ = 0.1 mm / 0.1 mrad, far above any lidar information along it).
  double remap_information = 1e8;
  // lidar_only: apply the remapping (false: only report the scan degenerate).
  bool remap = true;

  void Validate() const;  // throws std::invalid_argument naming the bad field
};

struct DegeneracyReport {
  bool analysed = false;
  // Normalised eigenvalues ν (ascending) of the translation and rotation blocks.
  Vec3 translation_eigenvalues = Vec3::Zero();
  Vec3 rotation_eigenvalues = Vec3::Zero();
  // Degenerate directions, body frame, unit, tangent order [ρ; φ] (a translation direction has
  // φ = 0, a rotation one ρ = 0); the least constrained first.
  std::vector<Vec6> directions;
  // Along directions[0] (when there is one): the lidar's and the rest of the window's whitened
  // information (prior_information < 0: not computed).
  double lidar_information = 0.0;
  double prior_information = -1.0;
  bool remapped = false;  // lidar_only: the remapping prior was added

  int num_degenerate() const { return static_cast<int>(directions.size()); }
  // "t:x,y,z" / "r:x,y,z" of directions[0], or "-".
  std::string DirectionString() const;
};

// Information of `residuals` on the tangent of the pose state `pose` (all other states they touch
// held), in the body frame: A is δ_state = A·δ_body.
Mat6 PoseInformation(const SlidingWindow& window,
                     const std::vector<ceres::ResidualBlockId>& residuals, StateId pose,
                     const Mat6& A);

// Marginal information on `pose` (body frame) of every residual of the window except `excluded`.
Mat6 OtherInformation(const SlidingWindow& window,
                      const std::vector<ceres::ResidualBlockId>& excluded, StateId pose,
                      const Mat6& A);

// Information of `residuals` on the tangents of `states` (in that order, constant or not), every
// other non-constant state they touch marginalised (Schur complement): what these residuals alone
// say about `states`. OtherInformation is this on one pose, moved into the body frame.
Eigen::MatrixXd MarginalInformation(const SlidingWindow& window,
                                    const std::vector<ceres::ResidualBlockId>& residuals,
                                    const std::vector<StateId>& states);

// The eigen-analysis of a body-frame lidar information H (6×6, [ρ; φ]).
DegeneracyReport AnalyseDegeneracy(const Mat6& H, const DegeneracyOptions& options);

// The remapping prior's square-root information on the pose state's tangent (δ_state = A·δ_body):
// √w·Σ_u u uᵀ·A⁻¹ (6×6, rank = number of directions).
Mat6 RemapSqrtInformation(const DegeneracyReport& report, const DegeneracyOptions& options,
                          const Mat6& A);

}  // namespace ctlio::lio
