#include "ctlio/factors/gp/singer_prior.h"

#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::gp {
namespace {

using RowMajor18x6 = Eigen::Matrix<double, 18, 6, Eigen::RowMajor>;
using Diag = AxisBlockMatrix<6>::Diag;

inline auto AsDiag(const Diag& d) { return d.matrix().asDiagonal(); }

}  // namespace

SingerPrior::SingerPrior(const SingerModel<6>& model, double dt)
    : phi_(model.TransitionBlocks(dt)), sqrt_info_(model.SqrtInformationBlocks(dt)) {
  w_phi_ = sqrt_info_ * phi_;
}

SingerPrior::Vector18 SingerPrior::Error(const KnotState& k, const KnotState& k1) const {
  const LocalVariables lv(k, k1, false);
  Vector18 e;
  for (int r = 0; r < 3; ++r) {
    e.segment<6>(6 * r) = lv.gamma[r] - (phi_.block(r, 1) * k.velocity.array() +
                                         phi_.block(r, 2) * k.acceleration.array())
                                            .matrix();
  }
  return e;
}

bool SingerPrior::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const KnotState k = ReadKnotState(parameters[0], parameters[1], parameters[2]);
  const KnotState k1 = ReadKnotState(parameters[3], parameters[4], parameters[5]);
  const bool jac = jacobians != nullptr;
  const LocalVariables lv(k, k1, jac);

  // e_r = γ_{k+1,r} − Σ_c Φ_rc γ_{k,c} (γ_{k,0} = 0); r = W·e with W block lower triangular.
  Eigen::Array<double, 6, 1> e[3];
  for (int r = 0; r < 3; ++r) {
    e[r] = lv.gamma[r].array() - phi_.block(r, 1) * k.velocity.array() -
           phi_.block(r, 2) * k.acceleration.array();
  }
  Eigen::Map<Vector18> res(residuals);
  for (int r = 0; r < 3; ++r) {
    Diag s = sqrt_info_.block(r, 0) * e[0];
    for (int c = 1; c <= r; ++c) s += sqrt_info_.block(r, c) * e[c];
    res.segment<6>(6 * r) = s.matrix();
  }
  if (!jac) return true;

  // ∂e/∂δT_{k+1} = [J⁻¹; D1J⁻¹; D2J⁻¹], ∂e/∂δT_k = −∂e/∂δT_{k+1}·Ad(T21) (knot_state.h).
  if (jacobians[0] != nullptr || jacobians[3] != nullptr) {
    Mat6 X[3];
    X[0] = lv.J_inv;
    X[1].noalias() = lv.D1 * lv.J_inv;
    X[2].noalias() = lv.D2 * lv.J_inv;
    Eigen::Matrix<double, 18, 6> Z;
    for (int r = 0; r < 3; ++r) {
      auto b = Z.middleRows<6>(6 * r);
      b.noalias() = AsDiag(sqrt_info_.block(r, 0)) * X[0];
      for (int c = 1; c <= r; ++c) b.noalias() += AsDiag(sqrt_info_.block(r, c)) * X[c];
    }
    if (jacobians[3] != nullptr) LiftPoseJacobian<18>(Z, parameters[3], jacobians[3]);
    if (jacobians[0] != nullptr) {
      const Eigen::Matrix<double, 18, 6> Z0 = -Z * lv.Ad21;
      LiftPoseJacobian<18>(Z0, parameters[0], jacobians[0]);
    }
  }
  // ∂e/∂ϖ_k = −Φ_{:,1}, ∂e/∂ϖ̇_k = −Φ_{:,2}: diagonal blocks of −WΦ.
  for (int c = 1; c < 3; ++c) {
    if (jacobians[c] == nullptr) continue;
    Eigen::Map<RowMajor18x6> J(jacobians[c]);
    J.setZero();
    for (int r = 0; r < 3; ++r) J.block<6, 6>(6 * r, 0).diagonal() = -w_phi_.block(r, c).matrix();
  }
  // ∂e/∂ϖ_{k+1} = [0; J⁻¹; E], ∂e/∂ϖ̇_{k+1} = [0; 0; J⁻¹].
  if (jacobians[4] != nullptr) {
    Eigen::Map<RowMajor18x6> J(jacobians[4]);
    J.topRows<6>().setZero();
    J.middleRows<6>(6) = AsDiag(sqrt_info_.block(1, 1)) * lv.J_inv;
    J.bottomRows<6>() =
        AsDiag(sqrt_info_.block(2, 1)) * lv.J_inv + AsDiag(sqrt_info_.block(2, 2)) * lv.E;
  }
  if (jacobians[5] != nullptr) {
    Eigen::Map<RowMajor18x6> J(jacobians[5]);
    J.topRows<12>().setZero();
    J.bottomRows<6>() = AsDiag(sqrt_info_.block(2, 2)) * lv.J_inv;
  }
  return true;
}

}  // namespace ctlio::gp
