// Dense marginalisation algebra (solvers/schur_complement.h) against direct inversion.
#include "ctlio/solvers/schur_complement.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace ctlio {
namespace {

Eigen::MatrixXd RandomJacobian(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd J(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) J(i, j) = n(rng);
  return J;
}

Eigen::VectorXd RandomVector(std::mt19937& rng, int n) {
  std::normal_distribution<double> d(0.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = d(rng);
  return v;
}

double RelativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1e-300, b.norm());
}

// The Schur complement's inverse is the kept block of H⁻¹ (marginal covariance) and its solution
// is the kept part of the full solution.
TEST(SchurComplement, MatchesMarginalOfFullInverse) {
  std::mt19937 rng(7);
  const int n = 12;
  const Eigen::MatrixXd J = RandomJacobian(rng, 20, n);
  const Eigen::VectorXd r = RandomVector(rng, 20);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = J.transpose() * r;
  const std::vector<int> keep = {11, 2, 5, 7, 0};
  const std::vector<int> marg = {1, 3, 4, 6, 8, 9, 10};
  const SchurComplementResult s = SchurComplement(H, b, keep, marg);
  EXPECT_EQ(s.marginalized_rank, 7);
  const Eigen::MatrixXd P = H.inverse();
  const Eigen::VectorXd x = -H.ldlt().solve(b);
  Eigen::MatrixXd P_kk(5, 5);
  Eigen::VectorXd x_k(5);
  for (int i = 0; i < 5; ++i) {
    x_k[i] = x[keep[i]];
    for (int j = 0; j < 5; ++j) P_kk(i, j) = P(keep[i], keep[j]);
  }
  EXPECT_LT(RelativeError(s.information.inverse(), P_kk), 1e-12);
  EXPECT_LT(RelativeError(-s.information.ldlt().solve(s.vector), x_k), 1e-12);
  EXPECT_TRUE(s.information.isApprox(s.information.transpose(), 0.0));
}

TEST(SchurComplement, LeadingBlockConvenienceAgrees) {
  std::mt19937 rng(8);
  const Eigen::MatrixXd J = RandomJacobian(rng, 15, 9);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = RandomVector(rng, 9);
  const SchurComplementResult a = SchurComplementLeading(H, b, 4);
  const SchurComplementResult c = SchurComplement(H, b, {4, 5, 6, 7, 8}, {0, 1, 2, 3});
  EXPECT_LT(RelativeError(a.information, c.information), 1e-15);
  EXPECT_LT(RelativeError(a.vector, c.vector), 1e-15);
}

// Coordinates whose information differs by 16 orders of magnitude (GP priors, SPEC §2) are still
// inverted exactly: the threshold acts on the Jacobi-scaled matrix.
TEST(SchurComplement, PseudoInverseIsExactForBadlyScaledWellPosedMatrix) {
  std::mt19937 rng(9);
  const int n = 9;
  const Eigen::MatrixXd J = RandomJacobian(rng, 12, n);
  Eigen::VectorXd s(n);
  s << 1e8, 1e-8, 1.0, 1e5, 1e-3, 1e2, 3e7, 1e-6, 10.0;
  const Eigen::MatrixXd H = s.asDiagonal() * (J.transpose() * J) * s.asDiagonal();
  int rank = -1;
  const Eigen::MatrixXd Hinv = PseudoInverse(H, kDefaultRelativeEigenvalueThreshold, &rank);
  EXPECT_EQ(rank, n);
  // Compare in the unit-free metric: diag(s)·H⁻¹·diag(s) = (JᵀJ)⁻¹.
  const Eigen::MatrixXd unit_free = s.asDiagonal() * Hinv * s.asDiagonal();
  EXPECT_LT(RelativeError(unit_free, (J.transpose() * J).inverse()), 1e-12);
}

// A marginalised variable nothing observes (zero row) and one observed only through a
// combination with another (rank-deficient block): finite results equal to the limit of a
// vanishing regulariser on the unobserved direction.
TEST(SchurComplement, SingularMarginalBlockGivesFiniteLimit) {
  std::mt19937 rng(10);
  const int n = 8;  // m = {0, 1, 2}, k = {3..7}
  Eigen::MatrixXd J = RandomJacobian(rng, 14, n);
  J.col(0).setZero();   // variable 0: no information at all
  J.col(2) = J.col(1);  // variables 1, 2: only their sum is observed
  const Eigen::VectorXd r = RandomVector(rng, 14);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = J.transpose() * r;
  const SchurComplementResult s = SchurComplementLeading(H, b, 3);
  EXPECT_EQ(s.marginalized_rank, 1);
  EXPECT_TRUE(s.information.allFinite());
  EXPECT_TRUE(s.vector.allFinite());

  Eigen::MatrixXd H_reg = H;
  H_reg.topLeftCorner(3, 3) += 1e-7 * Eigen::MatrixXd::Identity(3, 3);
  const Eigen::MatrixXd Hmm = H_reg.topLeftCorner(3, 3);
  const Eigen::MatrixXd Hkm = H_reg.bottomLeftCorner(5, 3);
  const Eigen::MatrixXd expected =
      H_reg.bottomRightCorner(5, 5) - Hkm * Hmm.inverse() * Hkm.transpose();
  const Eigen::VectorXd expected_b = b.tail(5) - Hkm * Hmm.inverse() * b.head(3);
  EXPECT_LT(RelativeError(s.information, expected), 1e-6);
  EXPECT_LT(RelativeError(s.vector, expected_b), 1e-6);
}

TEST(SchurComplement, SquareRootReproducesInformation) {
  std::mt19937 rng(11);
  const int n = 7;
  Eigen::MatrixXd J = RandomJacobian(rng, 10, n);
  J.col(6) = 2.0 * J.col(3) - J.col(1);  // rank 6
  const Eigen::VectorXd r = RandomVector(rng, 10);
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = J.transpose() * r;
  Eigen::MatrixXd A;
  Eigen::VectorXd r0;
  const int rank = InformationSquareRoot(H, b, &A, &r0);
  EXPECT_EQ(rank, 6);
  ASSERT_EQ(A.rows(), 6);
  ASSERT_EQ(A.cols(), n);
  EXPECT_LT(RelativeError(A.transpose() * A, H), 1e-12);
  EXPECT_LT(RelativeError(A.transpose() * r0, b), 1e-12);
}

TEST(SchurComplement, ZeroInformationHasRankZero) {
  Eigen::MatrixXd A;
  Eigen::VectorXd r0;
  EXPECT_EQ(InformationSquareRoot(Eigen::MatrixXd::Zero(4, 4), Eigen::VectorXd::Zero(4), &A, &r0),
            0);
  EXPECT_EQ(A.rows(), 0);
  EXPECT_EQ(A.cols(), 4);
  const Eigen::MatrixXd P = PseudoInverse(Eigen::MatrixXd::Zero(3, 3));
  EXPECT_TRUE(P.allFinite());
  EXPECT_EQ(P.norm(), 0.0);
}

TEST(SchurComplement, RoundOffNegativeEigenvaluesAreDropped) {
  // An indefinite perturbation far below the threshold must not make the square root NaN.
  Eigen::MatrixXd H(2, 2);
  H << 1.0, 1.0, 1.0, 1.0 - 1e-15;  // eigenvalue ≈ −5e-16
  Eigen::MatrixXd A;
  Eigen::VectorXd r0;
  EXPECT_EQ(InformationSquareRoot(H, Eigen::Vector2d(1.0, 1.0), &A, &r0), 1);
  EXPECT_TRUE(A.allFinite());
  EXPECT_TRUE(r0.allFinite());
}

TEST(SchurComplement, BadInputThrows) {
  const Eigen::MatrixXd H = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd b = Eigen::VectorXd::Zero(3);
  EXPECT_THROW(SchurComplement(H, b, {0, 1}, {1}), std::invalid_argument);  // overlap
  EXPECT_THROW(SchurComplement(H, b, {0, 3}, {1}), std::invalid_argument);  // out of range
  EXPECT_THROW(SchurComplement(H, Eigen::VectorXd::Zero(2), {0}, {1}), std::invalid_argument);
  Eigen::MatrixXd bad = H;
  bad(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SchurComplementLeading(bad, b, 1), std::invalid_argument);
  try {
    SchurComplement(H, b, {0}, {5});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("schur_complement.cc"), std::string::npos);
  }
}

}  // namespace
}  // namespace ctlio
