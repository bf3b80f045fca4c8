// A small point-to-point ICP in the manner of KISS-ICP (Vizzo et al., RA-L 2023), to ask how a
// method of that kind fares on a pair of sweeps (docs/experiments/worlds-geometry.md): the
// target (one original point per voxel, or all) in a k-d tree, the source downsampled to one
// original point per voxel, nearest neighbours
// within a shrinking gate, and Gauss–Newton on SE(3) with Geman–McClure weights
//   w_i = κ² / (κ + |e_i|²)²,  e_i = T·s_i − t_i,
// (ρ(e) = ½e²/(κ + e²) as KISS-ICP writes it, κ in m² numerically),
// with the left perturbation T ← Exp(δ)·T, ∂e_i/∂δ = [I, −(T·s_i)^].
#pragma once

#include <vector>

#include "ctlio/manifolds/se3.h"

namespace ctlio::eval {

struct PointIcpOptions {
  double source_voxel = 0.5;                    // m
  double target_voxel = 0.0;                    // 0: every target point
  std::vector<double> gates = {2.0, 1.0, 0.5};  // correspondence distance per stage [m]
  int iterations = 40;                          // per stage, at most
  double kernel = 0.1;  // κ of the Geman–McClure weight, as a fraction of the stage's gate²
  // κ itself when > 0 (KISS-ICP: σ/3 of its adaptive threshold), instead of kernel·gate².
  double kernel_absolute = 0.0;
  double converged = 1e-5;  // |δ| below which a stage ends
  // Levenberg damping: (H + μ·diag(H))·δ = −g; 0 = Gauss–Newton. Keeps a step along a direction
  // the correspondences hardly constrain (a road between walls, a lawn) from running off.
  double damping = 0.0;
};

struct PointIcpResult {
  SE3 target_from_source;
  int correspondences = 0;  // in the last iteration
};

// T_target_source mapping `source` onto `target`, started at `initial`.
PointIcpResult RegisterPointToPoint(const std::vector<Vec3>& source,
                                    const std::vector<Vec3>& target, const SE3& initial,
                                    const PointIcpOptions& options = {});

}  // namespace ctlio::eval
