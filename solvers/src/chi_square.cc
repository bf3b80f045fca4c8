#include "ctlio/solvers/chi_square.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ctlio {

double ChiSquareQuantile(double dof, double probability) {
  if (!(dof > 0.0) || !std::isfinite(dof) || !(probability > 0.0 && probability < 1.0)) {
    throw std::invalid_argument(
        "ChiSquareQuantile: needs dof > 0 and a probability in (0, 1), got dof " +
        std::to_string(dof) + ", probability " + std::to_string(probability));
  }
  return boost::math::quantile(boost::math::chi_squared(dof), probability);
}

}  // namespace ctlio
