#include "ctlio/solvers/chi_square.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace ctlio {
namespace {

// χ²(2) is the exponential distribution with mean 2: its quantile is −2 ln(1 − p) in closed form.
TEST(ChiSquareQuantile, TwoDegreesOfFreedomIsTheClosedForm) {
  for (const double p : {0.001, 0.025, 0.5, 0.975, 0.999}) {
    EXPECT_NEAR(ChiSquareQuantile(2.0, p), -2.0 * std::log(1.0 - p), 1e-9) << "p " << p;
  }
}

// Tabulated 0.999 quantiles (scipy.stats.chi2.ppf(0.999, k)) of the IMU terms' dof the misfit
// test uses: the baseline's preintegrated factor (9) and Singer-LIO's 20 samples of one (60) and
// both (120) sensors.
TEST(ChiSquareQuantile, MatchesTabulatedValues) {
  EXPECT_NEAR(ChiSquareQuantile(9.0, 0.999), 27.877, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(60.0, 0.999), 99.607, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(120.0, 0.999), 173.617, 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(3.0, 0.025), 0.2158, 1e-4);
}

TEST(ChiSquareQuantile, RejectsWhatHasNoQuantile) {
  EXPECT_THROW(ChiSquareQuantile(0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(-1.0, 0.5), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(3.0, 0.0), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(3.0, 1.0), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(std::nan(""), 0.5), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(3.0, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace ctlio
