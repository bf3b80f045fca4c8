// The GP motion prior of estimator 2 between consecutive states [p, v, a] (SPEC §2).
#pragma once

#include <ceres/cost_function.h>

#include <memory>

#include "ctlio/study/simulation.h"

namespace ctlio::study {

// e = W·(x_{k+1} − Φ(Δt)·x_k), WᵀW = Q(Δt)⁻¹ for the prior (σ² = Qc, α).
std::unique_ptr<ceres::CostFunction> MakeGpPriorFactor(const PriorConfig& prior, double dt);

}  // namespace ctlio::study
