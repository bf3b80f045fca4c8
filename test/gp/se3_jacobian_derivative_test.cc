// ∂(J(ξ)w)/∂ξ and ∂(J⁻¹(ξ)w)/∂ξ (se3_jacobian_derivative.h, used by the GP interpolator's
// Jacobians, SPEC §2) against central differences, and their coefficients on both sides of the
// series switch.
#include "ctlio/factors/gp/se3_jacobian_derivative.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/gradient_check.h"

namespace ctlio::gp {
namespace {

using ctlio::testing::RandomVec6;

// Central differences with a fixed step of 1e-6 (the maps are smooth; no Ridders needed).
TEST(Se3JacobianDerivativeTest, MatchesNumericDifferentiation) {
  std::mt19937 rng(7);
  for (double angle : {0.0, 1e-9, 1e-4, 0.3, 1.0, 1.999, 2.0, 2.001, 2.5, 3.1, 3.14159}) {
    for (int trial = 0; trial < 3; ++trial) {
      Vec6 xi = RandomVec6(rng, 2.0);
      const Vec3 axis = xi.tail<3>().normalized();
      xi.tail<3>() = angle * axis;
      const Vec6 w = RandomVec6(rng, 3.0);
      const Mat6 D = LeftJacobianVectorDerivative(xi, w);
      Mat6 Dn;
      const double h = 1e-6;
      for (int j = 0; j < 6; ++j) {
        Vec6 e = Vec6::Zero();
        e[j] = h;
        Dn.col(j) = (se3::LeftJacobian(xi + e) * w - se3::LeftJacobian(xi - e) * w) / (2 * h);
      }
      EXPECT_LE((D - Dn).norm(), 1e-8 * (1.0 + Dn.norm())) << "angle " << angle << "\n"
                                                           << D << "\n\n"
                                                           << Dn;
      const Mat6 Ji = se3::LeftJacobianInverse(xi);
      const Mat6 Di = LeftJacobianInverseVectorDerivative(xi, Ji, w);
      for (int j = 0; j < 6; ++j) {
        Vec6 e = Vec6::Zero();
        e[j] = h;
        Dn.col(j) =
            (se3::LeftJacobianInverse(xi + e) * w - se3::LeftJacobianInverse(xi - e) * w) / (2 * h);
      }
      EXPECT_LE((Di - Dn).norm(), 1e-7 * (1.0 + Dn.norm())) << "angle " << angle;
    }
  }
}

TEST(Se3JacobianDerivativeTest, CoefficientSeriesAndClosedFormsAgreeAtSwitch) {
  const Se3JacobianCoefficients a(std::nextafter(4.0, 0.0)), b(4.0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(a.c[i], b.c[i], 1e-14 * std::abs(b.c[i]));
    EXPECT_NEAR(a.dc[i], b.dc[i], 1e-13 * std::abs(b.dc[i]));
  }
}

}  // namespace
}  // namespace ctlio::gp
