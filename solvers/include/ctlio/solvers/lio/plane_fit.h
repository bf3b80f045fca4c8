// The PCA plane of a set of map points (SPEC §4): centroid, normal (eigenvector of the smallest
// covariance eigenvalue) and the planarity weight ((σ2 − σ3)/σ1)². One fit from the first and
// second moments, used both by the k-nearest-neighbour association (moments of the neighbours)
// and by the voxel map's per-voxel planes (moments kept up to date on insertion).
#pragma once

#include "ctlio/manifolds/types.h"

namespace ctlio::lio {

struct PlaneFit {
  Vec3 centroid = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, eigenvector of the smallest covariance eigenvalue
  // Unit eigenvector of the middle eigenvalue: with the normal, the two axes across a line-like
  // set (PlaneAssociator's fit across a ring line, LidarFrontendOptions::line_neighbourhood_ratio).
  Vec3 middle_axis = Vec3::UnitY();
  // σ1 ≥ σ2 ≥ σ3: square roots of the covariance eigenvalues.
  double sigma1 = 0.0, sigma2 = 0.0, sigma3 = 0.0;
  // ((σ2 − σ3)/σ1)² (SPEC §4): ≈1 for a clean plane, ≈0 for a line or an isotropic blob.
  double planarity_weight = 0.0;
};

// The plane through points with this mean and (population) covariance; false for a degenerate
// (zero-spread) set.
bool FitPlaneFromMoments(const Vec3& mean, const Mat3& covariance, PlaneFit* plane);

}  // namespace ctlio::lio
