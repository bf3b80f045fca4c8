#include "ctlio/study/prior_factor.h"

#include "ctlio/factors/gp/vector_prior.h"

namespace ctlio::study {

std::unique_ptr<ceres::CostFunction> MakeGpPriorFactor(const PriorConfig& prior, double dt) {
  return std::unique_ptr<ceres::CostFunction>(gp::MakeSingerPrior1D(prior.alpha, prior.qc, dt));
}

}  // namespace ctlio::study
