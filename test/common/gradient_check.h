// Shared test helpers: Jacobians of ctlio cost functions against numeric
// differentiation on the parameter blocks' manifolds (ceres::GradientChecker
// compares J_ambient·PlusJacobian with central differences through Plus).
#pragma once

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::testing {

// Returns a GradientChecker verdict with the worst relative error reported.
inline ::testing::AssertionResult JacobiansMatchNumeric(
    const ceres::CostFunction& cost, const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters, double relative_precision = 1e-7) {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-3;
  options.max_num_ridders_extrapolations = 10;
  // GradientChecker differentiates with Ridders' extrapolation, which gives the
  // ~1e-10 accuracy that tight checks need.
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double const*> params = parameters;
  if (checker.Probe(params.data(), relative_precision, &results)) {
    return ::testing::AssertionSuccess() << "max relative error " << results.maximum_relative_error;
  }
  return ::testing::AssertionFailure() << results.error_log;
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
