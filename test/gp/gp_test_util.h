// Jacobian check for the GP tests: ceres::GradientChecker's probe (Ridders' numeric
// differentiation on the blocks' manifolds), compared block by block with an error measured
// against the block's scale: max|J − J_num| ≤ tol · max(1, max|J_num|). GradientChecker's own
// per-entry relative error flags entries of 1e-9 that are off by 1e-14 in absolute terms (pure
// differencing noise, e.g. at rotations of 1e-7 rad), which says nothing about the Jacobian.
#pragma once

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <vector>

namespace ctlio::gp::testing {

inline ::testing::AssertionResult JacobiansMatchNumericScaled(
    const ceres::CostFunction& cost, const std::vector<const ceres::Manifold*>& manifolds,
    const std::vector<const double*>& parameters, double tol) {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-3;
  options.max_num_ridders_extrapolations = 10;
  ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  std::vector<const double*> params = parameters;
  checker.Probe(params.data(), 1.0, &results);
  if (!results.return_value) return ::testing::AssertionFailure() << "Evaluate failed";
  std::ostringstream log;
  double worst = 0.0;
  bool ok = true;
  for (std::size_t b = 0; b < results.local_jacobians.size(); ++b) {
    const auto& J = results.local_jacobians[b];
    const auto& N = results.local_numeric_jacobians[b];
    const double scale = std::max(1.0, N.cwiseAbs().maxCoeff());
    const double err = (J - N).cwiseAbs().maxCoeff() / scale;
    worst = std::max(worst, err);
    if (!(err <= tol)) {
      ok = false;
      log << "block " << b << ": scaled error " << err << " > " << tol << "\nanalytic\n"
          << J << "\nnumeric\n"
          << N << "\n";
    }
  }
  if (ok) return ::testing::AssertionSuccess() << "worst scaled error " << worst;
  return ::testing::AssertionFailure() << log.str();
}

}  // namespace ctlio::gp::testing
