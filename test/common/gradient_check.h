// The one Jacobian check of ctlio's tests: a cost function's analytic Jacobians against numeric
// differentiation on its parameter blocks' manifolds.
//
// How the numeric Jacobian is obtained: ceres::GradientChecker::Probe with Ridders' extrapolated
// central differences (NumericDiffOptions: ridders_relative_initial_step_size = 1e-3, i.e. an
// initial step of 1e-3·max(|x|, 1) per tangent coordinate, up to 10 extrapolations, which reaches
// ~1e-10 relative accuracy on smooth residuals). Both sides are tangent-space Jacobians
// (GradientChecker's local_jacobians: J_ambient·PlusJacobian, and differences taken through
// Plus), so the check is the one the solver sees. GradientChecker's own verdict is NOT used.
//
// The criterion (one for every test), on every entry of every block:
//
//     |J − J_num| ≤ max(relative · max(|J|, |J_num|), absolute),
//
// relative = 1e-7 and absolute = 1e-10 by default; a test may pass other values (tighter, or
// looser with the reason in a comment). `absolute` is the floor for entries that are zero or tiny:
// the numeric derivative carries noise of ~1e-12 × (residual size / step) there, so a purely
// relative test would judge differencing noise (e.g. entries that vanish analytically, scale with
// (τ − t)², or sit at rotations of 1e-9 rad). How it relates to the criteria the tests used before:
// GradientChecker::Probe's own verdict is the same relative test but allows `relative` in
// absolute terms wherever either entry is zero (this one allows `absolute` ≤ `relative` there);
// a block-scaled test |J − J_num| ≤ tol·max(1, max|J_block|) is never tighter than this one with
// relative = absolute = tol.
#pragma once

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::testing {

inline constexpr double kJacobianRelativeTolerance = 1e-7;
inline constexpr double kJacobianAbsoluteTolerance = 1e-10;

// Passes when every entry meets the criterion above; the message reports the worst ratio
// |J − J_num| / bound (≤ 1 on success), or the failing block with both Jacobians.
inline ::testing::AssertionResult JacobiansMatchNumeric(
    const ceres::CostFunction& cost, const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters, double relative = kJacobianRelativeTolerance,
    double absolute = kJacobianAbsoluteTolerance) {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-3;
  options.max_num_ridders_extrapolations = 10;
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  std::vector<const double*> params = parameters;
  checker.Probe(params.data(), relative, &results);
  if (!results.return_value) {
    return ::testing::AssertionFailure() << "Evaluate failed: " << results.error_log;
  }
  double worst = 0.0;
  for (std::size_t b = 0; b < results.local_jacobians.size(); ++b) {
    const auto& J = results.local_jacobians[b];
    const auto& N = results.local_numeric_jacobians[b];
    for (int i = 0; i < J.rows(); ++i) {
      for (int j = 0; j < J.cols(); ++j) {
        const double error = std::abs(J(i, j) - N(i, j));
        const double bound =
            std::max(relative * std::max(std::abs(J(i, j)), std::abs(N(i, j))), absolute);
        if (!(error <= bound)) {
          return ::testing::AssertionFailure()
                 << "block " << b << " entry (" << i << ", " << j << "): |J - J_num| = " << error
                 << " > " << bound << " (relative " << relative << ", absolute " << absolute
                 << ")\nanalytic\n"
                 << J << "\nnumeric\n"
                 << N;
        }
        worst = std::max(worst, error / bound);
      }
    }
  }
  return ::testing::AssertionSuccess() << "worst |J - J_num| / bound = " << worst;
}

inline SE3 RandomPose(std::mt19937& rng, double max_angle, double max_translation) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec3 axis(u(rng), u(rng), u(rng));
  axis.normalize();
  const double angle = max_angle * std::abs(u(rng));
  const Vec3 r(u(rng), u(rng), u(rng));
  return SE3(so3::Exp(angle * axis), max_translation * r);
}

inline Vec6 RandomVec6(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Vec6 v;
  for (int i = 0; i < 6; ++i) v[i] = u(rng);
  return v;
}

// Pose block storage helper: 7 doubles in PoseManifold's layout.
inline std::vector<double> PoseParameters(const SE3& T) {
  std::vector<double> x(7);
  PoseManifold::Store(T, x.data());
  return x;
}

}  // namespace ctlio::testing
