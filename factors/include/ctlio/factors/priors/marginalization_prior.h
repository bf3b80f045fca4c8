// MarginalizationPrior: the Gaussian prior left behind by marginalising states out of a window
// (SPEC §5), on any set of parameter blocks with their manifolds:
//
//     r(x) = A · [x₁ ⊟ x̄₁; …; x_n ⊟ x̄_n] + r0,
//
// A = √Λ (rank × Σ tangent sizes) and r0 come from the Schur complement (see
// solvers/schur_complement.h: InformationSquareRoot), x̄ are the kept states' values at the time of
// marginalisation and stay FIXED (first-estimate Jacobians: the linearisation point of the
// information never moves). ⊟ is each block's manifold Minus (SPEC §1):
//
//   nullptr (Euclidean, any size n):  x ⊟ x̄ = x − x̄,                 d/dx = I_n.
//   ctlio::PoseManifold (7 → 6):      X ⊟ X̄ = ξ = Log(X·X̄⁻¹),         d/dδ = 𝒥⁻¹(ξ),
//   ctlio::RotationManifold (4 → 3):  C ⊟ C̄ = φ = Log(C·C̄ᵀ),          d/dδ = J⁻¹(φ),
//
// where δ is the left perturbation X ← Exp(δ)·X of SPEC §1: Log(Exp(δ)·Exp(ξ)) ≈ ξ + 𝒥⁻¹(ξ)·δ
// (BCH, left Jacobian). Note that at x ≠ x̄ this is NOT MinusJacobian(x̄) (that is only the
// derivative at x = x̄): the prior is used far from x̄ after the window moves (or with large
// rotations, e.g. a pose measurement factor), so the exact derivative is required. The ambient
// Jacobian written for Ceres is J_tangent · Lift(x) (LiftPoseJacobian / LiftRotationJacobian
// convention of pose_manifold.h), so that Ceres, GradientChecker and Covariance see J_tangent.
//
// Any other ceres::Manifold is rejected at construction (std::invalid_argument): the exact
// derivative of its Minus away from x̄ is not available through the ceres::Manifold interface.
//
// With r0 = 0 and A = a square-root information, the same class is a unary Gaussian prior or
// measurement on any mix of poses, rotations and vectors (e.g. a pose measurement
// r = W·Log(T·T̄⁻¹) with T̄ the measured pose).
//
// Evaluate allocates nothing (all per-block work is fixed-size, residual accumulated column by
// column for Euclidean blocks).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <vector>

namespace ctlio {

class MarginalizationPrior final : public ceres::CostFunction {
 public:
  enum class BlockType { kEuclidean, kPose, kRotation };

  // manifolds[i] ∈ {nullptr, PoseManifold*, RotationManifold*}; ambient_sizes[i] must match the
  // manifold (7, 4) or be > 0 for nullptr; linearization_points[i] points at ambient_sizes[i]
  // doubles (copied). sqrt_information is rank × Σ tangent sizes (rank ≥ 1), r0 has rank rows.
  // Throws std::invalid_argument (message with file:line) on any mismatch or non-finite input.
  MarginalizationPrior(const std::vector<const ceres::Manifold*>& manifolds,
                       const std::vector<int>& ambient_sizes,
                       const std::vector<const double*>& linearization_points,
                       const Eigen::MatrixXd& sqrt_information, const Eigen::VectorXd& r0);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // Classifies a manifold; throws std::invalid_argument for an unsupported one.
  static BlockType TypeOf(const ceres::Manifold* manifold);

  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  BlockType block_type(int i) const { return blocks_[i].type; }
  int tangent_size(int i) const { return blocks_[i].tangent_size; }
  int tangent_offset(int i) const { return blocks_[i].tangent_offset; }
  const double* linearization_point(int i) const { return &points_[blocks_[i].point_offset]; }
  const Eigen::MatrixXd& sqrt_information() const { return sqrt_information_; }
  const Eigen::VectorXd& r0() const { return r0_; }

 private:
  struct Block {
    BlockType type;
    int ambient_size;
    int tangent_size;
    int tangent_offset;  // first column of this block in sqrt_information_
    int point_offset;    // first entry of x̄ in points_
  };
  std::vector<Block> blocks_;
  std::vector<double> points_;  // x̄ of every block, concatenated
  Eigen::MatrixXd sqrt_information_;
  Eigen::VectorXd r0_;
};

}  // namespace ctlio
