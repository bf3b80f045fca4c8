#include "ctlio/solvers/lio/plane_fit.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace ctlio::lio {

bool FitPlaneFromMoments(const Vec3& mean, const Mat3& covariance, PlaneFit* plane) {
  // Closed-form 3×3 eigen-decomposition (several times faster than the iterative QL solver;
  // the plane normal's eigenvalue is well separated for the planar patches that pass the gate).
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(covariance);
  if (es.info() != Eigen::Success) return false;
  // Eigenvalues ascending: λ0 ≤ λ1 ≤ λ2, σ1 = √λ2 ≥ σ2 = √λ1 ≥ σ3 = √λ0.
  const Vec3 lambda = es.eigenvalues().cwiseMax(0.0);
  plane->sigma1 = std::sqrt(lambda[2]);
  plane->sigma2 = std::sqrt(lambda[1]);
  plane->sigma3 = std::sqrt(lambda[0]);
  if (!(plane->sigma1 > 0.0)) return false;
  const double a2d = (plane->sigma2 - plane->sigma3) / plane->sigma1;
  plane->planarity_weight = a2d * a2d;
  plane->centroid = mean;
  plane->normal = es.eigenvectors().col(0).normalized();
  plane->middle_axis = es.eigenvectors().col(1);
  return true;
}

}  // namespace ctlio::lio
