// GP motion prior between consecutive knots on a vector space (SPEC §2, last line):
//   r = W·(x_{k+1} − Φ x_k),  WᵀW = Q⁻¹,
// for any linear model (WNOA [p; v], WNOJ / Singer [p; v; a], N stacked axes). Dim is the
// state size of one knot; the 1D study uses VectorGpPrior<3> (one Singer/WNOJ axis, state
// [p, v, a]) or VectorGpPrior<2> (WNOA [p, v]), everything fixed-size.
// Parameter blocks: x_k (Dim), x_{k+1} (Dim).
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "ctlio/factors/gp/motion_model.h"

namespace ctlio::gp {

template <int Dim>
class VectorGpPrior final : public ceres::SizedCostFunction<Dim, Dim, Dim> {
 public:
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  using Vector = Eigen::Matrix<double, Dim, 1>;

  // Φ and W with WᵀW = Q⁻¹ (W from SingerSqrtInformation, SingerModel::SqrtInformation, ...).
  VectorGpPrior(const Matrix& transition, const Matrix& sqrt_information)
      : sqrt_info_(sqrt_information), minus_w_phi_(-sqrt_information * transition) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Vector> x0(parameters[0]), x1(parameters[1]);
    Eigen::Map<Vector> r(residuals);
    r.noalias() = sqrt_info_ * x1;
    r.noalias() += minus_w_phi_ * x0;
    if (jacobians != nullptr) {
      using RowMajor = Eigen::Matrix<double, Dim, Dim, Eigen::RowMajor>;
      if (jacobians[0] != nullptr) Eigen::Map<RowMajor>(jacobians[0], Dim, Dim) = minus_w_phi_;
      if (jacobians[1] != nullptr) Eigen::Map<RowMajor>(jacobians[1], Dim, Dim) = sqrt_info_;
    }
    return true;
  }

  const Matrix& SqrtInformation() const { return sqrt_info_; }

 private:
  Matrix sqrt_info_;
  Matrix minus_w_phi_;  // −W·Φ
};

// One Singer axis (α = 0: WNOJ), knot state [p, v, a].
inline VectorGpPrior<3>* MakeSingerPrior1D(double alpha, double qc, double dt) {
  return new VectorGpPrior<3>(SingerTransition(alpha, dt), SingerSqrtInformation(alpha, qc, dt));
}

// One WNOA axis, knot state [p, v].
inline VectorGpPrior<2>* MakeWnoaPrior1D(double qc, double dt) {
  return new VectorGpPrior<2>(WnoaTransition(dt), WnoaSqrtInformation(qc, dt));
}

// N Singer axes, knot state [p(N); v(N); a(N)].
template <int N>
VectorGpPrior<3 * N>* MakeSingerVectorPrior(const SingerModel<N>& model, double dt) {
  return new VectorGpPrior<3 * N>(model.Transition(dt), model.SqrtInformation(dt));
}

}  // namespace ctlio::gp
