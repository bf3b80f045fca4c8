#include "ctlio/factors/priors/marginalization_prior.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio {
namespace {

[[noreturn]] void Throw(int line, const std::string& what) {
  std::ostringstream msg;
  msg << __FILE__ << ":" << line << ": MarginalizationPrior: " << what;
  throw std::invalid_argument(msg.str());
}

using RowMajorMap =
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

}  // namespace

MarginalizationPrior::BlockType MarginalizationPrior::TypeOf(const ceres::Manifold* manifold) {
  if (manifold == nullptr) return BlockType::kEuclidean;
  if (dynamic_cast<const PoseManifold*>(manifold) != nullptr) return BlockType::kPose;
  if (dynamic_cast<const RotationManifold*>(manifold) != nullptr) return BlockType::kRotation;
  Throw(__LINE__,
        "unsupported manifold (ambient " + std::to_string(manifold->AmbientSize()) + ", tangent " +
            std::to_string(manifold->TangentSize()) +
            "): only nullptr (Euclidean), ctlio::PoseManifold and ctlio::RotationManifold have an "
            "exact Minus derivative away from the linearisation point");
}

MarginalizationPrior::MarginalizationPrior(const std::vector<const ceres::Manifold*>& manifolds,
                                           const std::vector<int>& ambient_sizes,
                                           const std::vector<const double*>& linearization_points,
                                           const Eigen::MatrixXd& sqrt_information,
                                           const Eigen::VectorXd& r0)
    : sqrt_information_(sqrt_information), r0_(r0) {
  const size_t n = manifolds.size();
  if (n == 0) Throw(__LINE__, "needs at least one parameter block");
  if (ambient_sizes.size() != n || linearization_points.size() != n) {
    Throw(__LINE__, "got " + std::to_string(n) + " manifolds, " +
                        std::to_string(ambient_sizes.size()) + " sizes and " +
                        std::to_string(linearization_points.size()) + " linearisation points");
  }
  int tangent_total = 0;
  int point_total = 0;
  for (size_t i = 0; i < n; ++i) {
    Block b;
    b.type = TypeOf(manifolds[i]);
    b.ambient_size = ambient_sizes[i];
    b.tangent_size = manifolds[i] == nullptr ? ambient_sizes[i] : manifolds[i]->TangentSize();
    if (b.ambient_size <= 0 ||
        (manifolds[i] != nullptr && manifolds[i]->AmbientSize() != b.ambient_size)) {
      Throw(__LINE__, "block " + std::to_string(i) + " has ambient size " +
                          std::to_string(b.ambient_size) + " which does not fit its manifold");
    }
    if (linearization_points[i] == nullptr) {
      Throw(__LINE__, "block " + std::to_string(i) + " has no linearisation point");
    }
    b.tangent_offset = tangent_total;
    b.point_offset = point_total;
    tangent_total += b.tangent_size;
    point_total += b.ambient_size;
    blocks_.push_back(b);
    points_.insert(points_.end(), linearization_points[i],
                   linearization_points[i] + b.ambient_size);
    mutable_parameter_block_sizes()->push_back(b.ambient_size);
  }
  for (double v : points_) {
    if (!std::isfinite(v)) Throw(__LINE__, "linearisation point has NaN/Inf entries");
  }
  if (sqrt_information_.rows() < 1 || sqrt_information_.cols() != tangent_total ||
      r0_.size() != sqrt_information_.rows()) {
    std::ostringstream what;
    what << "sqrt_information is " << sqrt_information_.rows() << "x" << sqrt_information_.cols()
         << " and r0 has " << r0_.size() << " rows; expected rank x " << tangent_total
         << " (rank >= 1) and rank rows";
    Throw(__LINE__, what.str());
  }
  if (!sqrt_information_.allFinite() || !r0_.allFinite()) {
    Throw(__LINE__, "sqrt_information or r0 has NaN/Inf entries");
  }
  set_num_residuals(static_cast<int>(sqrt_information_.rows()));
}

bool MarginalizationPrior::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const int rows = num_residuals();
  Eigen::Map<Eigen::VectorXd> r(residuals, rows);
  r = r0_;
  for (size_t i = 0; i < blocks_.size(); ++i) {
    const Block& b = blocks_[i];
    const double* x = parameters[i];
    const double* x_bar = &points_[b.point_offset];
    const auto A = sqrt_information_.middleCols(b.tangent_offset, b.tangent_size);
    double* J = jacobians != nullptr ? jacobians[i] : nullptr;
    switch (b.type) {
      case BlockType::kEuclidean: {
        for (int j = 0; j < b.ambient_size; ++j) r.noalias() += A.col(j) * (x[j] - x_bar[j]);
        if (J != nullptr) RowMajorMap(J, rows, b.ambient_size) = A;
        break;
      }
      case BlockType::kPose: {
        // ξ = Log(X·X̄⁻¹); d ξ / d δ = 𝒥⁻¹(ξ) for X ← Exp(δ)·X.
        Vec6 xi;
        PoseManifold().Minus(x, x_bar, xi.data());
        r.noalias() += A * xi;
        if (J != nullptr) {
          const Eigen::Matrix<double, 6, 7> D =
              se3::LeftJacobianInverse(xi) * PoseManifold::Lift(x);
          RowMajorMap(J, rows, 7).noalias() = A * D;
        }
        break;
      }
      case BlockType::kRotation: {
        // φ = Log(C·C̄ᵀ); d φ / d δ = J⁻¹(φ) for C ← Exp(δ)·C.
        Vec3 phi;
        RotationManifold().Minus(x, x_bar, phi.data());
        r.noalias() += A * phi;
        if (J != nullptr) {
          const Eigen::Matrix<double, 3, 4> D =
              so3::LeftJacobianInverse(phi) * RotationManifold::Lift(x);
          RowMajorMap(J, rows, 4).noalias() = A * D;
        }
        break;
      }
    }
  }
  return true;
}

}  // namespace ctlio
