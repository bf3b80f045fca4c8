// The square-root form of a batch of point rows (continuous_point_to_plane_batch.h, "Square-root
// form"): from the Gauss–Newton Hessian H = JᵀJ and gradient g = Jᵀr of N rows on W tangent
// coordinates, the W rows R (RᵀR = H) and r₀ (Rᵀr₀ = g) on H's informative subspace, by the
// rank-revealing Cholesky factorisation with complete pivoting of the Jacobi-scaled H; the rank
// stops where the largest remaining pivot is at most `threshold`. Shared by the batches of the GP
// knots (ContinuousPointToPlaneBatch) and of the navigation state
// (PointToPlaneWorldCalibratedBatch).
#pragma once

#include <Eigen/Core>

namespace ctlio {

// Reads the lower triangle of *H (overwritten). Returns false on a non-finite H or g.
bool BatchSquareRoot(Eigen::MatrixXd* H, const Eigen::VectorXd& g, double threshold,
                     Eigen::MatrixXd* R, Eigen::VectorXd* r0);

}  // namespace ctlio
