#include "ctlio/factors/gp/interpolator.h"

#include <optional>
#include <string>
#include <type_traits>

namespace ctlio::gp {
namespace {

using Diag = AxisBlockMatrix<6>::Diag;

// Writes the (rows × 6) image M·[X0; X1; X2] of one knot variable's dγ(τ) into columns
// [c, c+6) of out, M = [[J, 0, 0], [M21, J, 0], [M31, M32, J]] (interpolator.h).
struct OutputMap {
  Mat6 J, M21, M31, M32;
};

template <int R>
void Apply(const OutputMap& M, const Mat6& X0, const Mat6& X1, const Mat6& X2, int c,
           Eigen::Matrix<double, R, 18>* out) {
  out->template block<6, 6>(0, c).noalias() = M.J * X0;
  if constexpr (R == 18) {
    auto b1 = out->template block<6, 6>(6, c);
    b1.noalias() = M.M21 * X0;
    b1.noalias() += M.J * X1;
    auto b2 = out->template block<6, 6>(12, c);
    b2.noalias() = M.M31 * X0;
    b2.noalias() += M.M32 * X1;
    b2.noalias() += M.J * X2;
  }
}

// Same for a variable whose dγ(τ) blocks are diagonal (knot k's ϖ, ϖ̇: the columns of Λ).
template <int R>
void ApplyDiag(const OutputMap& M, const Diag& d0, const Diag& d1, const Diag& d2, int c,
               Eigen::Matrix<double, R, 18>* out) {
  out->template block<6, 6>(0, c).noalias() = M.J * d0.matrix().asDiagonal();
  if constexpr (R == 18) {
    out->template block<6, 6>(6, c).noalias() =
        M.M21 * d0.matrix().asDiagonal() + M.J * d1.matrix().asDiagonal();
    out->template block<6, 6>(12, c).noalias() = M.M31 * d0.matrix().asDiagonal() +
                                                 M.M32 * d1.matrix().asDiagonal() +
                                                 M.J * d2.matrix().asDiagonal();
  }
}

// The one implementation behind GpInterpolator (omega, k1 non-null) and GpExtrapolator
// (both null, lambda = Φ(τ−t_k)). R = 6: pose only; R = 18: full state.
// `shared`: the interval's LocalVariables (with Jacobians) when the caller has them already.
template <int R>
void Evaluate(const AxisBlockMatrix<6>& lambda, const AxisBlockMatrix<6>* omega, const KnotState& k,
              const KnotState* k1, const LocalVariables* shared, SE3* T, Vec6* velocity,
              Vec6* acceleration, Eigen::Matrix<double, R, 18>* J_k,
              Eigen::Matrix<double, R, 18>* J_k1) {
  const bool jac = J_k != nullptr || J_k1 != nullptr;
  const bool two_knots = k1 != nullptr || shared != nullptr;
  // γ(τ) = Λγ_k + Ωγ_{k+1}, γ_k = [0; ϖ_k; ϖ̇_k].
  Vec6 g[3];
  for (int r = 0; r < 3; ++r) {
    g[r] = (lambda.block(r, 1) * k.velocity.array() + lambda.block(r, 2) * k.acceleration.array())
               .matrix();
  }
  std::optional<LocalVariables> own;
  const LocalVariables* lv = shared;
  if (two_knots) {
    if (lv == nullptr) lv = &own.emplace(k, *k1, jac);
    for (int r = 0; r < 3; ++r) {
      g[r].array() += omega->block(r, 0) * lv->gamma[0].array() +
                      omega->block(r, 1) * lv->gamma[1].array() +
                      omega->block(r, 2) * lv->gamma[2].array();
    }
  }
  const Vec6& xi = g[0];
  const SE3 E = SE3::Exp(xi);
  if (T != nullptr) *T = E * k.pose;
  if (R == 6 && !jac) return;

  OutputMap M;
  M.J = se3::LeftJacobian(xi);
  Vec6 vel, v;
  if constexpr (R == 18) {
    vel.noalias() = M.J * g[1];
    const Mat6 Xd = se3::CurlyHat(g[1]);
    v = g[2];
    v.noalias() += 0.5 * Xd * vel;
    if (velocity != nullptr) *velocity = vel;
    if (acceleration != nullptr) acceleration->noalias() = M.J * v;
    if (!jac) return;
    M.M21 = LeftJacobianVectorDerivative(xi, g[1]);
    const Mat6 K = M.J * Xd;  // J·ξ̇^⋏
    M.M31 = LeftJacobianVectorDerivative(xi, v);
    M.M31.noalias() += 0.5 * K * M.M21;
    M.M32.noalias() = 0.5 * K * M.J;
    M.M32.noalias() -= 0.5 * M.J * se3::CurlyHat(vel);
  }

  // Knot k+1, and through Ad(T21) knot k's pose (∂γ_{k+1}/∂δT_k = −∂γ_{k+1}/∂δT_{k+1}·Ad21).
  Eigen::Matrix<double, R, 6> out_T1;
  if (two_knots) {
    const LocalVariables& l = *lv;
    const AxisBlockMatrix<6>& O = *omega;
    auto diag = [](const Diag& d) { return d.matrix().asDiagonal(); };
    Mat6 X[3];
    if constexpr (R == 6) {
      Mat6 R0 = diag(O.block(0, 1)) * l.D1;
      R0.noalias() += diag(O.block(0, 2)) * l.D2;
      R0.diagonal() += O.block(0, 0).matrix();
      X[0].noalias() = R0 * l.J_inv;
    } else {
      const Mat6 DJ1 = l.D1 * l.J_inv, DJ2 = l.D2 * l.J_inv;
      for (int r = 0; r < 3; ++r) {
        X[r].noalias() = diag(O.block(r, 0)) * l.J_inv;
        X[r].noalias() += diag(O.block(r, 1)) * DJ1;
        X[r].noalias() += diag(O.block(r, 2)) * DJ2;
      }
    }
    Eigen::Matrix<double, R, 18> tmp;
    Eigen::Matrix<double, R, 18>* t1 = J_k1 != nullptr ? J_k1 : &tmp;
    Apply<R>(M, X[0], X[1], X[2], 0, t1);
    out_T1 = t1->template leftCols<6>();
    if (J_k1 != nullptr) {
      for (int r = 0; r < 3; ++r) {
        X[r].noalias() = diag(O.block(r, 1)) * l.J_inv;
        X[r].noalias() += diag(O.block(r, 2)) * l.E;
      }
      Apply<R>(M, X[0], X[1], X[2], 6, J_k1);
      for (int r = 0; r < 3; ++r) X[r].noalias() = diag(O.block(r, 2)) * l.J_inv;
      Apply<R>(M, X[0], X[1], X[2], 12, J_k1);
    }
  }
  if (J_k != nullptr) {
    if (two_knots) {
      J_k->template leftCols<6>().noalias() = -out_T1 * lv->Ad21;
    } else {
      J_k->template leftCols<6>().setZero();
    }
    J_k->template block<6, 6>(0, 0) += E.Adjoint();
    ApplyDiag<R>(M, lambda.block(0, 1), lambda.block(1, 1), lambda.block(2, 1), 6, J_k);
    ApplyDiag<R>(M, lambda.block(0, 2), lambda.block(1, 2), lambda.block(2, 2), 12, J_k);
  }
}

// Rows [h, h+N) of layer L (0: δT, 1: ϖ, 2: ϖ̇) of M·[diag(d0); diag(d1); diag(d2)], i.e.
// Σ_r M_{Lr}[h, h+N)·diag(d_r) with M = [[J, 0, 0], [M21, J, 0], [M31, M32, J]]: the image of a
// knot variable whose dγ(τ)_r = diag(d_r)·(its contribution), restricted to the wanted rows.
template <int N>
Eigen::Matrix<double, N, 6> RowsTimesDiag(const OutputMap& M, int L, int h, const Diag& d0,
                                          const Diag& d1, const Diag& d2) {
  Eigen::Matrix<double, N, 6> B;
  const auto rows = [h](const Mat6& A) { return A.template middleRows<N>(h); };
  if (L == 0) {
    B.noalias() = rows(M.J) * d0.matrix().asDiagonal();
  } else if (L == 1) {
    B.noalias() = rows(M.M21) * d0.matrix().asDiagonal() + rows(M.J) * d1.matrix().asDiagonal();
  } else {
    B.noalias() = rows(M.M31) * d0.matrix().asDiagonal() + rows(M.M32) * d1.matrix().asDiagonal() +
                  rows(M.J) * d2.matrix().asDiagonal();
  }
  return B;
}

// The row-selective state evaluation (GpInterpolator::StateRows). Per selected row range of
// layer L, with B_c = Σ_r M_{Lr}·diag(Ω_rc) and dγ_{k+1} from knot_state.h:
//   ∂/∂δT_{k+1} = (B_0 + B_1·D1 + B_2·D2)·J⁻¹,  ∂/∂ϖ_{k+1} = B_1·J⁻¹ + B_2·E,
//   ∂/∂ϖ̇_{k+1} = B_2·J⁻¹,  ∂/∂δT_k = −∂/∂δT_{k+1}·Ad21 (+ Ad(Exp ξ) on the pose rows),
//   ∂/∂ϖ_k = Σ_r M_{Lr}·diag(Λ_r1),  ∂/∂ϖ̇_k = Σ_r M_{Lr}·diag(Λ_r2).
// With `rate` (and Λ', Ω' in `dot`), also rows of ẋ(τ) = M·(Λ'γ_k + Ω'γ_{k+1}) (interpolator.h).
void EvaluateRows(const AxisBlockMatrix<6>& lambda, const AxisBlockMatrix<6>& omega,
                  const KnotState& k, const KnotState* k1, const LocalVariables* shared,
                  unsigned rows, KnotState* x, StateJacobian* J_k, StateJacobian* J_k1,
                  const AxisBlockMatrix<6>* lambda_dot = nullptr,
                  const AxisBlockMatrix<6>* omega_dot = nullptr, StateRate* rate = nullptr) {
  const bool jac = (J_k != nullptr || J_k1 != nullptr) && (rows & kAllStateRows) != 0;
  const bool with_rate = rate != nullptr && (rows & kAllStateRows) != 0;
  std::optional<LocalVariables> own;
  const LocalVariables& lv = shared != nullptr ? *shared : own.emplace(k, *k1, jac);
  Vec6 g[3];
  for (int r = 0; r < 3; ++r) {
    g[r] = (lambda.block(r, 1) * k.velocity.array() + lambda.block(r, 2) * k.acceleration.array() +
            omega.block(r, 0) * lv.gamma[0].array() + omega.block(r, 1) * lv.gamma[1].array() +
            omega.block(r, 2) * lv.gamma[2].array())
               .matrix();
  }
  const Vec6& xi = g[0];
  const SE3 E = SE3::Exp(xi);
  OutputMap M;
  M.J = se3::LeftJacobian(xi);
  const Vec6 vel = M.J * g[1];
  const Mat6 Xd = se3::CurlyHat(g[1]);
  Vec6 v = g[2];
  v.noalias() += 0.5 * Xd * vel;
  if (x != nullptr) {
    x->pose = E * k.pose;
    x->velocity = vel;
    x->acceleration.noalias() = M.J * v;
  }
  if (!jac && !with_rate) return;
  const int top_layer = (rows & 48u) != 0 ? 2 : (rows & 12u) != 0 ? 1 : 0;
  if (top_layer == 1) {
    M.M21 = LeftJacobianVectorDerivative(xi, g[1]);
  } else if (top_layer == 2) {
    const Vec6 w[2] = {g[1], v};
    Mat6 D[2];
    LeftJacobianVectorDerivatives<2>(xi, w, D);
    M.M21 = D[0];
    // Only the wanted rows of M31 = ∂(Jv)/∂ξ + ½Jξ̇^⋏M21 and M32 = ½J(ξ̇^⋏J − ϖ^⋏) are formed
    // (RowsTimesDiag reads no others).
    const Mat6 Xv = se3::CurlyHat(vel);
    const auto acc_rows = [&](auto n, int h) {
      constexpr int N = decltype(n)::value;
      const Eigen::Matrix<double, N, 6> K = M.J.middleRows<N>(h) * Xd;  // rows of J·ξ̇^⋏
      auto m31 = M.M31.middleRows<N>(h);
      m31 = D[1].middleRows<N>(h);
      m31.noalias() += 0.5 * K * M.M21;
      auto m32 = M.M32.middleRows<N>(h);
      m32.noalias() = 0.5 * K * M.J;
      m32.noalias() -= 0.5 * M.J.middleRows<N>(h) * Xv;
    };
    const unsigned m = (rows >> 4) & 3u;
    if (m == 3u) {
      acc_rows(std::integral_constant<int, 6>(), 0);
    } else {
      acc_rows(std::integral_constant<int, 3>(), m == 1u ? 0 : 3);
    }
  }
  // dγ(τ)/dτ = Λ'γ_k + Ω'γ_{k+1} (γ_k = [0; ϖ_k; ϖ̇_k]).
  Vec6 dg[3];
  if (with_rate) {
    for (int q = 0; q < 3; ++q) {
      dg[q] = (lambda_dot->block(q, 1) * k.velocity.array() +
               lambda_dot->block(q, 2) * k.acceleration.array() +
               omega_dot->block(q, 0) * lv.gamma[0].array() +
               omega_dot->block(q, 1) * lv.gamma[1].array() +
               omega_dot->block(q, 2) * lv.gamma[2].array())
                  .matrix();
    }
  }
  const auto range = [&](int L, auto n, int h) {
    constexpr int N = decltype(n)::value;
    const int r = 6 * L + h;
    if (with_rate) {
      // Rows of M·dγ/dτ, layer L: Σ_q M_{Lq}·dγ_q.
      auto out = rate->template segment<N>(r);
      out.noalias() = M.J.middleRows<N>(h) * dg[L];
      if (L == 1) out.noalias() += M.M21.middleRows<N>(h) * dg[0];
      if (L == 2) {
        out.noalias() += M.M31.middleRows<N>(h) * dg[0];
        out.noalias() += M.M32.middleRows<N>(h) * dg[1];
      }
    }
    if (!jac) return;
    const auto col = [&](const AxisBlockMatrix<6>& A, int c) {
      return RowsTimesDiag<N>(M, L, h, A.block(0, c), A.block(1, c), A.block(2, c));
    };
    const Eigen::Matrix<double, N, 6> B1 = col(omega, 1), B2 = col(omega, 2);
    Eigen::Matrix<double, N, 6> S = col(omega, 0);
    S.noalias() += B1 * lv.D1;
    S.noalias() += B2 * lv.D2;
    Eigen::Matrix<double, N, 6> T1;
    T1.noalias() = S * lv.J_inv;
    if (J_k1 != nullptr) {
      J_k1->template block<N, 6>(r, 0) = T1;
      auto c1 = J_k1->template block<N, 6>(r, 6);
      c1.noalias() = B1 * lv.J_inv;
      c1.noalias() += B2 * lv.E;
      J_k1->template block<N, 6>(r, 12).noalias() = B2 * lv.J_inv;
    }
    if (J_k != nullptr) {
      auto c0 = J_k->template block<N, 6>(r, 0);
      c0.noalias() = -T1 * lv.Ad21;
      if (L == 0) c0 += E.Adjoint().template middleRows<N>(h);
      J_k->template block<N, 6>(r, 6) = col(lambda, 1);
      J_k->template block<N, 6>(r, 12) = col(lambda, 2);
    }
  };
  for (int L = 0; L <= top_layer; ++L) {
    const unsigned m = (rows >> (2 * L)) & 3u;
    if (m == 3u) {
      range(L, std::integral_constant<int, 6>(), 0);
    } else if (m != 0u) {
      range(L, std::integral_constant<int, 3>(), m == 1u ? 0 : 3);
    }
  }
}

[[noreturn]] void Throw(int line, const std::string& what) {
  internal::ThrowInvalid(__FILE__, line, what);
}

}  // namespace

GpInterpolator::GpInterpolator(const SingerModel<6>& model, double t_k, double t_k1, double tau,
                               bool with_time_derivative) {
  if (!(t_k1 > t_k) || !(tau >= t_k) || !(tau <= t_k1)) {
    Throw(__LINE__,
          "GpInterpolator needs t_k < t_k1 and t_k <= tau <= t_k1, got t_k=" + std::to_string(t_k) +
              " t_k1=" + std::to_string(t_k1) + " tau=" + std::to_string(tau));
  }
  const double d1 = tau - t_k, d2 = t_k1 - tau, dT = t_k1 - t_k;
  const auto& alpha = model.alpha();
  Eigen::Matrix3d L, O, Ld, Od;
  std::shared_ptr<Rates> rates;
  if (with_time_derivative) rates = std::make_shared<Rates>();
  for (int i = 0; i < 6; ++i) {
    if (i == 0 || alpha[i] != alpha[i - 1]) {
      // Qc cancels in Ω and Λ, so the dimensionless shapes with Qc = 1 suffice.
      const SingerShape sT = EvaluateSingerShape(alpha[i] * dT);
      const Eigen::Matrix3d W = SingerSqrtInformationFromShape(sT, 1.0, dT);
      const Eigen::Matrix3d PhiT = SingerModel<6>::ShapeTransition(sT, dT);
      // Evaluated once for Q(τ−t_k) and Φ(τ−t_k) (the shapes are most of this constructor's
      // cost, paid per firing of a scan).
      const SingerShape s1 = EvaluateSingerShape(alpha[i] * d1);
      if (d1 == 0.0) {
        O.setZero();
      } else {
        const SingerShape s2 = EvaluateSingerShape(alpha[i] * d2);
        const Eigen::Matrix3d Q1 = SingerModel<6>::Scaled(s1, d1);
        const Eigen::Matrix3d Phi2 = SingerModel<6>::ShapeTransition(s2, d2);
        O = Q1 * Phi2.transpose() * W.transpose() * W;
      }
      const Eigen::Matrix3d Phi1 = SingerModel<6>::ShapeTransition(s1, d1);
      L = Phi1 - O * PhiT;
      if (rates) {
        // Ω' = AΩ + e₃e₃ᵀΦ(t_{k+1}−τ)ᵀQ(T)⁻¹, Λ' = AΦ(τ−t_k) − Ω'Φ(T) (header; Qc = 1).
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
        A(0, 1) = 1.0;
        A(1, 2) = 1.0;
        A(2, 2) = -alpha[i];
        const Eigen::Matrix3d Phi2 =
            SingerModel<6>::ShapeTransition(EvaluateSingerShape(alpha[i] * d2), d2);
        Od = A * O;
        Od.row(2) += (Phi2.transpose() * W.transpose() * W).row(2);
        Ld = A * Phi1 - Od * PhiT;
      }
    }
    lambda_.SetAxis(i, L);
    omega_.SetAxis(i, O);
    if (rates) {
      rates->lambda_dot.SetAxis(i, Ld);
      rates->omega_dot.SetAxis(i, Od);
    }
  }
  rates_ = std::move(rates);
}

void GpInterpolator::Pose(const KnotState& k, const KnotState& k1, SE3* T, PoseJacobian* J_k,
                          PoseJacobian* J_k1) const {
  Evaluate<6>(lambda_, &omega_, k, &k1, nullptr, T, nullptr, nullptr, J_k, J_k1);
}

void GpInterpolator::Pose(const KnotState& k, const LocalVariables& local, SE3* T,
                          PoseJacobian* J_k, PoseJacobian* J_k1) const {
  Evaluate<6>(lambda_, &omega_, k, nullptr, &local, T, nullptr, nullptr, J_k, J_k1);
}

void GpInterpolator::State(const KnotState& k, const KnotState& k1, KnotState* x,
                           StateJacobian* J_k, StateJacobian* J_k1) const {
  KnotState tmp;
  KnotState* out = x != nullptr ? x : &tmp;
  Evaluate<18>(lambda_, &omega_, k, &k1, nullptr, &out->pose, &out->velocity, &out->acceleration,
               J_k, J_k1);
}

void GpInterpolator::StateRows(const KnotState& k, const KnotState& k1, unsigned rows, KnotState* x,
                               StateJacobian* J_k, StateJacobian* J_k1) const {
  EvaluateRows(lambda_, omega_, k, &k1, nullptr, rows, x, J_k, J_k1);
}

void GpInterpolator::StateRows(const KnotState& k, const LocalVariables& local, unsigned rows,
                               KnotState* x, StateJacobian* J_k, StateJacobian* J_k1) const {
  EvaluateRows(lambda_, omega_, k, nullptr, &local, rows, x, J_k, J_k1);
}

void GpInterpolator::StateRows(const KnotState& k, const KnotState& k1, unsigned rows, KnotState* x,
                               StateJacobian* J_k, StateJacobian* J_k1, StateRate* rate) const {
  if (rate != nullptr && !rates_) {
    Throw(__LINE__, "GpInterpolator::StateRows: the rate needs with_time_derivative");
  }
  EvaluateRows(lambda_, omega_, k, &k1, nullptr, rows, x, J_k, J_k1,
               rates_ ? &rates_->lambda_dot : nullptr, rates_ ? &rates_->omega_dot : nullptr, rate);
}

void GpInterpolator::PoseAt(const KnotState& k, const LocalVariables& local, PoseAtTau* out) const {
  // ξ = row 0 of γ(τ) = Λγ_k + Ωγ_{k+1}, summed as in Evaluate (so T(τ) is bit-identical).
  Vec6 xi =
      (lambda_.block(0, 1) * k.velocity.array() + lambda_.block(0, 2) * k.acceleration.array())
          .matrix();
  xi.array() += omega_.block(0, 0) * local.gamma[0].array() +
                omega_.block(0, 1) * local.gamma[1].array() +
                omega_.block(0, 2) * local.gamma[2].array();
  const SE3 E = SE3::Exp(xi);
  out->T = E * k.pose;
  out->J = se3::LeftJacobian(xi);
  out->Ad = E.Adjoint();
}

void GpInterpolator::ChainPose(const PoseAtTau& at, const LocalVariables& local,
                               const Eigen::Matrix<double, 1, 6>& u,
                               Eigen::Matrix<double, 1, 18>* J_k,
                               Eigen::Matrix<double, 1, 18>* J_k1) const {
  using Row6 = Eigen::Matrix<double, 1, 6>;
  const Row6 v = u * at.J;
  const auto scaled = [&v](const Diag& d) -> Row6 {
    return v.cwiseProduct(d.matrix().transpose());
  };
  const Row6 a0 = scaled(omega_.block(0, 0)), a1 = scaled(omega_.block(0, 1)),
             a2 = scaled(omega_.block(0, 2));
  Row6 t1 = a0 * local.J_inv;
  t1.noalias() += a1 * local.DJ1;
  t1.noalias() += a2 * local.DJ2;
  if (J_k1 != nullptr) {
    J_k1->leftCols<6>() = t1;
    auto w = J_k1->middleCols<6>(6);
    w.noalias() = a1 * local.J_inv;
    w.noalias() += a2 * local.E;
    J_k1->rightCols<6>().noalias() = a2 * local.J_inv;
  }
  if (J_k != nullptr) {
    auto p = J_k->leftCols<6>();
    p.noalias() = u * at.Ad;
    p.noalias() -= t1 * local.Ad21;
    J_k->middleCols<6>(6) = scaled(lambda_.block(0, 1));
    J_k->rightCols<6>() = scaled(lambda_.block(0, 2));
  }
}

GpExtrapolator::GpExtrapolator(const SingerModel<6>& model, double t_k, double tau) {
  if (!(tau >= t_k)) {
    Throw(__LINE__, "GpExtrapolator needs tau >= t_k, got t_k=" + std::to_string(t_k) +
                        " tau=" + std::to_string(tau));
  }
  if (tau == t_k) {
    for (int i = 0; i < 3; ++i) phi_.block(i, i).setOnes();
  } else {
    phi_ = model.TransitionBlocks(tau - t_k);
  }
}

void GpExtrapolator::Pose(const KnotState& k, SE3* T, PoseJacobian* J_k) const {
  Evaluate<6>(phi_, nullptr, k, nullptr, nullptr, T, nullptr, nullptr, J_k, nullptr);
}

void GpExtrapolator::State(const KnotState& k, KnotState* x, StateJacobian* J_k) const {
  KnotState tmp;
  KnotState* out = x != nullptr ? x : &tmp;
  Evaluate<18>(phi_, nullptr, k, nullptr, nullptr, &out->pose, &out->velocity, &out->acceleration,
               J_k, nullptr);
}

}  // namespace ctlio::gp
