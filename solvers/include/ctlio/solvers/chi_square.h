// Quantiles of the χ² distribution, the one place ctlio computes them: the misfit test of the
// window's covariance (lio/misfit_covariance.h) and the NEES consistency bands of the 1D study
// (apps/study, after Bar-Shalom et al., "Estimation with Applications to Tracking and
// Navigation", §5.4.2).
#pragma once

namespace ctlio {

// q such that P(χ²_dof ≤ q) = probability (the exact inverse CDF). dof > 0 (not necessarily an
// integer: an average over m samples of dimension d is χ²_{m·d} / m) and probability in (0, 1);
// otherwise std::invalid_argument.
double ChiSquareQuantile(double dof, double probability);

}  // namespace ctlio
