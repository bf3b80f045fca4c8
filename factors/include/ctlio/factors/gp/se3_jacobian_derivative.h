// Derivative of the SE(3) left Jacobian applied to a vector, ∂(J(ξ)w)/∂ξ, and of its inverse,
// ∂(J⁻¹(ξ)w)/∂ξ: what the GP prior and interpolator (SPEC §2) need to differentiate
// γ_{k+1} = [ξ21; J⁻¹ϖ; ½ϖ^⋏J⁻¹ϖ + J⁻¹ϖ̇] and ϖ(τ) = J(ξ(τ))ξ̇(τ) exactly (the reference code
// drops these terms, which is why its interpolator Jacobians fail numeric checks).
//
// Method. With A = ξ^⋏ (se3::CurlyHat), A⁵ = −2θ²A³ − θ⁴A (θ = |φ|), so
//   J(ξ) = I + c1·A + c2·A² + c3·A³ + c4·A⁴     (Barfoot, State Estimation, eq. 7.95)
// with c1 = (4 − θsinθ − 4cosθ)/(2θ²), c2 = (4θ − 5sinθ + θcosθ)/(2θ³),
//      c3 = (2 − θsinθ − 2cosθ)/(2θ⁴), c4 = (2θ − 3sinθ + θcosθ)/(2θ⁵).
// Because A·y = −y^⋏·ξ, ∂(Aⁿw)/∂ξ = −Σ_{k<n} Aᵏ (A^{n−1−k}w)^⋏, and curlyhat is linear, so
//   ∂(J w)/∂ξ = −[z0^⋏ + A(z1^⋏ + A(z2^⋏ + A z3^⋏))] + 2(Σ cₙ'·Aⁿw)[0, φᵀ],
// z_k = Σ_{m=0}^{3−k} c_{m+k+1} A^m w, cₙ' = dcₙ/dθ². And J⁻¹ = (J)⁻¹ gives
//   ∂(J⁻¹w)/∂ξ = −J⁻¹ · ∂(J u)/∂ξ |_{u = J⁻¹w}.
// The coefficients cancel for small θ; below θ = 2 they are evaluated by their Taylor series
// in θ² (13 terms, exact rational coefficients rounded once; truncation < 1e-18), above by the
// closed forms (cancellation there costs < 1e-14 relative).
#pragma once

#include <cmath>

#include "ctlio/manifolds/se3.h"

namespace ctlio::gp {

struct Se3JacobianCoefficients {
  double c[4];   // c1 … c4
  double dc[4];  // dcₙ/dθ²

  explicit Se3JacobianCoefficients(double theta2) {
    if (theta2 < 4.0) {
      // clang-format off
      constexpr double kC1[] = {0.5, 0, -0.0013888888888888889, 4.9603174603174603e-05, -8.2671957671957675e-07, 8.3507027951472401e-09, -5.7353727988648621e-11, 2.867686399432431e-13, -1.0933444878010359e-15, 3.2882540986497319e-18, -8.0071122532055161e-21, 1.6117375710961184e-23, -2.7275558895472774e-26};
      constexpr double kD1[] = {0, -0.0027777777777777779, 0.00014880952380952382, -3.306878306878307e-06, 4.17535139757362e-08, -3.4412236793189173e-10, 2.0073804796027017e-12, -8.7467559024082875e-15, 2.9594286887847588e-17, -8.0071122532055158e-20, 1.7729113282057302e-22, -3.2730670674567324e-25};
      constexpr double kC2[] = {0.16666666666666666, 0, -0.00019841269841269841, 5.5114638447971785e-06, -7.5156325156325161e-08, 6.4236175347286453e-10, -3.8235818659099079e-12, 1.6868743526073125e-14, -5.7544446726370305e-17, 1.565835285071301e-19, -3.4813531535676156e-22, 6.4469502843844734e-25, -1.01020588501751e-27};
      constexpr double kD2[] = {0, -0.00039682539682539683, 1.6534391534391536e-05, -3.0062530062530064e-07, 3.211808767364323e-09, -2.2941491195459449e-11, 1.1808120468251188e-13, -4.6035557381096244e-16, 1.4092517565641709e-18, -3.4813531535676155e-21, 7.0916453128229206e-24, -1.2122470620210121e-26};
      constexpr double kC3[] = {0.041666666666666664, -0.0027777777777777779, 7.4404761904761911e-05, -1.1022927689594355e-06, 1.043837849393405e-08, -6.882447358637835e-11, 3.3456341326711696e-13, -1.249536557486898e-15, 3.6992858609809485e-18, -8.8967913924505729e-21, 1.7729113282057301e-23, -2.9755155158697568e-26, 4.263856008190789e-29};
      constexpr double kD3[] = {-0.0027777777777777779, 0.00014880952380952382, -3.306878306878307e-06, 4.17535139757362e-08, -3.4412236793189173e-10, 2.0073804796027017e-12, -8.7467559024082875e-15, 2.9594286887847588e-17, -8.0071122532055158e-20, 1.7729113282057302e-22, -3.2730670674567324e-25, 5.1166272098289475e-28};
      constexpr double kC4[] = {0.0083333333333333332, -0.00039682539682539683, 8.2671957671957678e-06, -1.0020843354176688e-07, 8.0295219184108074e-10, -4.5882982390918896e-12, 1.9680200780418645e-14, -6.5765081972994636e-17, 1.7615646957052136e-19, -3.8681701706306839e-22, 7.0916453128229206e-25, -1.1020427836554655e-27, 1.4702951752382032e-30};
      constexpr double kD4[] = {-0.00039682539682539683, 1.6534391534391536e-05, -3.0062530062530064e-07, 3.211808767364323e-09, -2.2941491195459449e-11, 1.1808120468251188e-13, -4.6035557381096244e-16, 1.4092517565641709e-18, -3.4813531535676155e-21, 7.0916453128229206e-24, -1.2122470620210121e-26, 1.7643542102858437e-29};
      // clang-format on
      c[0] = so3::Series(theta2, kC1);
      c[1] = so3::Series(theta2, kC2);
      c[2] = so3::Series(theta2, kC3);
      c[3] = so3::Series(theta2, kC4);
      dc[0] = so3::Series(theta2, kD1);
      dc[1] = so3::Series(theta2, kD2);
      dc[2] = so3::Series(theta2, kD3);
      dc[3] = so3::Series(theta2, kD4);
    } else {
      const double t = std::sqrt(theta2);
      const double s = std::sin(t), co = std::cos(t);
      const double t3 = theta2 * t, t4 = theta2 * theta2, t5 = t4 * t;
      c[0] = (4.0 - t * s - 4.0 * co) / (2.0 * theta2);
      c[1] = (4.0 * t - 5.0 * s + t * co) / (2.0 * t3);
      c[2] = (2.0 - t * s - 2.0 * co) / (2.0 * t4);
      c[3] = (2.0 * t - 3.0 * s + t * co) / (2.0 * t5);
      // dcₙ/dθ² = (dcₙ/dθ)/(2θ), simplified by sympy.
      const double a = -theta2 * co + 5.0 * t * s + 8.0 * co - 8.0;
      const double b = -theta2 * s - 7.0 * t * co - 8.0 * t + 15.0 * s;
      dc[0] = 0.25 * a / t4;
      dc[1] = 0.25 * b / t5;
      dc[2] = 0.25 * a / (t4 * theta2);
      dc[3] = 0.25 * b / (t5 * theta2);
    }
  }
};

// ∂(J(ξ)w)/∂ξ (6×6) for K vectors w at the same ξ (they share the coefficients), J the SE(3)
// left Jacobian of se3::LeftJacobian. Every matrix in the Horner recursion has the form
// [[X, Y], [0, X]] (like ξ^⋏ itself), so it runs on 3×3 blocks:
// A·[[X, Y], [0, X]] = [[φ^X, φ^Y + ρ^X], [0, φ^X]].
template <int K>
void LeftJacobianVectorDerivatives(const Vec6& xi, const Vec6 (&w)[K], Mat6 (&D)[K]) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  const Se3JacobianCoefficients k(phi.squaredNorm());
  const Mat3 P = so3::Hat(phi), R = so3::Hat(rho);
  for (int i = 0; i < K; ++i) {
    // y_m = Aᵐw, A·y = [φ×y_ρ + ρ×y_φ; φ×y_φ].
    Vec6 y[5];
    y[0] = w[i];
    for (int m = 1; m < 5; ++m) {
      y[m].head<3>() = phi.cross(y[m - 1].head<3>()) + rho.cross(y[m - 1].tail<3>());
      y[m].tail<3>() = phi.cross(y[m - 1].tail<3>());
    }
    // z_k = Σ_{m=0}^{3−k} c_{m+k+1} y_m (c 0-based: c[m+k]).
    Vec6 z[4];
    for (int kk = 0; kk < 4; ++kk) {
      z[kk] = k.c[kk] * y[0];
      for (int m = 1; m + kk < 4; ++m) z[kk] += k.c[m + kk] * y[m];
    }
    Mat3 X = so3::Hat(z[3].tail<3>()), Y = so3::Hat(z[3].head<3>());
    for (int kk = 2; kk >= 0; --kk) {
      Mat3 Yn = so3::Hat(z[kk].head<3>());
      Yn.noalias() += P * Y;
      Yn.noalias() += R * X;
      Mat3 Xn = so3::Hat(z[kk].tail<3>());
      Xn.noalias() += P * X;
      X = Xn;
      Y = Yn;
    }
    Mat6& Di = D[i];
    Di.topLeftCorner<3, 3>() = -X;
    Di.topRightCorner<3, 3>() = -Y;
    Di.bottomLeftCorner<3, 3>().setZero();
    Di.bottomRightCorner<3, 3>() = -X;
    const Vec6 g = 2.0 * (k.dc[0] * y[1] + k.dc[1] * y[2] + k.dc[2] * y[3] + k.dc[3] * y[4]);
    Di.rightCols<3>().noalias() += g * phi.transpose();
  }
}

inline Mat6 LeftJacobianVectorDerivative(const Vec6& xi, const Vec6& w) {
  const Vec6 ws[1] = {w};
  Mat6 D[1];
  LeftJacobianVectorDerivatives<1>(xi, ws, D);
  return D[0];
}

// a^⋏·M for a general 6×6 M on 3×3 blocks (a^⋏ = [[φ^, ρ^], [0, φ^]]).
inline Mat6 CurlyHatTimes(const Vec6& a, const Mat6& M) {
  const Mat3 P = so3::Hat(a.tail<3>()), R = so3::Hat(a.head<3>());
  Mat6 out;
  out.topRows<3>().noalias() = P * M.topRows<3>();
  out.topRows<3>().noalias() += R * M.bottomRows<3>();
  out.bottomRows<3>().noalias() = P * M.bottomRows<3>();
  return out;
}

// a^⋏·v = [φ×v_ρ + ρ×v_φ; φ×v_φ].
inline Vec6 CurlyHatTimes(const Vec6& a, const Vec6& v) {
  Vec6 out;
  out.head<3>() = a.tail<3>().cross(v.head<3>()) + a.head<3>().cross(v.tail<3>());
  out.tail<3>() = a.tail<3>().cross(v.tail<3>());
  return out;
}

// ∂(J⁻¹(ξ)w)/∂ξ given J⁻¹(ξ) (already needed by every caller).
inline Mat6 LeftJacobianInverseVectorDerivative(const Vec6& xi, const Mat6& J_inv, const Vec6& w) {
  return -J_inv * LeftJacobianVectorDerivative(xi, J_inv * w);
}

}  // namespace ctlio::gp
