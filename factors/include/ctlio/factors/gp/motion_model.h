// Per-axis Gaussian-process motion models of SPEC §2: WNOA ([p, v], white noise on
// acceleration), WNOJ ([p, v, a], white noise on jerk) and Singer (ȧ = −α·a + w).
//
// Every model is written in dimensionless form. With x = αΔt,
//   Φ = [[1, Δt, Δt²·g2(x)], [0, 1, Δt·g1(x)], [0, 0, e^{−x}]],
//   Q = Qc·D·q(x)·D,  D = diag(Δt^{5/2}, Δt^{3/2}, Δt^{1/2}),
// with g1 = (1 − e^{−x})/x, g2 = (x − 1 + e^{−x})/x² and q(x) the six entire functions
// q11 … q33 obtained by dividing the closed forms of SPEC §2 by Qc·Δt^p. q(0) is exactly the
// WNOJ matrix [[1/20, 1/8, 1/6], [1/8, 1/3, 1/2], [1/6, 1/2, 1]], so α = 0 IS WNOJ, and the
// scaling D keeps Q's inverse and Cholesky factor accurate for Δt from 1e-5 s to hours.
//
// The closed forms cancel catastrophically for small x (q11's numerator is O(x⁵) made of O(1)
// terms), so below kSingerSeriesSwitch they are replaced by their Taylor series (26 terms,
// exact rational coefficients). Error analysis against 60-digit arithmetic (see
// test/gp/motion_model_test.cc): the series is within 3e-16 relative of the truth for x ≤ 1.25
// (truncation < 1e-17), the closed form (with expm1) within 3e-15 for x ≥ 1.25, so the two
// branches agree to a few ulps at the switch (tested on both sides of it).
#pragma once

#include <Eigen/Core>
#include <array>
#include <stdexcept>
#include <string>

namespace ctlio::gp {

inline constexpr double kSingerSeriesSwitch = 1.25;

// Dimensionless Singer functions of x = αΔt (see the file comment).
struct SingerShape {
  double e;   // e^{−x}
  double g1;  // (1 − e^{−x})/x
  double g2;  // (x − 1 + e^{−x})/x²
  double q11, q12, q13, q22, q23, q33;
};

// Dispatches between the two evaluations below; x ≥ 0.
SingerShape EvaluateSingerShape(double x);
// Taylor series in x (accurate for x ≤ kSingerSeriesSwitch; exposed for the continuity test).
SingerShape SingerShapeSeries(double x);
// Closed forms of SPEC §2 divided by Qc·Δt^p (accurate for x ≥ kSingerSeriesSwitch).
SingerShape SingerShapeClosedForm(double x);

// ---- Singer / WNOJ, one axis, state [p, v, a] ---------------------------------------------

// Φ(Δt); α = 0 gives WNOJ exactly.
Eigen::Matrix3d SingerTransition(double alpha, double dt);
// Q(Δt) = Qc ∫₀^Δt Φ(s) L Lᵀ Φ(s)ᵀ ds, L = [0, 0, 1]ᵀ; exact for every α ≥ 0, Δt > 0.
Eigen::Matrix3d SingerCovariance(double alpha, double qc, double dt);
// Q(Δt)⁻¹.
Eigen::Matrix3d SingerInformation(double alpha, double qc, double dt);
// Lower-triangular W with WᵀW = Q(Δt)⁻¹ (W = L⁻¹ for Q = LLᵀ): whitened error r = W·e.
Eigen::Matrix3d SingerSqrtInformation(double alpha, double qc, double dt);

inline Eigen::Matrix3d WnojTransition(double dt) { return SingerTransition(0.0, dt); }
inline Eigen::Matrix3d WnojCovariance(double qc, double dt) {
  return SingerCovariance(0.0, qc, dt);
}

// ---- WNOA, one axis, state [p, v] ----------------------------------------------------------
Eigen::Matrix2d WnoaTransition(double dt);
// Qc·[[Δt³/3, Δt²/2], [Δt²/2, Δt]].
Eigen::Matrix2d WnoaCovariance(double qc, double dt);
// Qc⁻¹·[[12/Δt³, −6/Δt²], [−6/Δt², 4/Δt]].
Eigen::Matrix2d WnoaInformation(double qc, double dt);
// Lower-triangular W with WᵀW = Q⁻¹.
Eigen::Matrix2d WnoaSqrtInformation(double qc, double dt);

namespace internal {
[[noreturn]] void ThrowInvalid(const char* file, int line, const std::string& what);
inline void CheckModelArguments(double alpha, double qc, double dt, const char* file, int line) {
  // Negated comparisons also reject NaN.
  if (!(dt > 0.0)) ThrowInvalid(file, line, "time step must be > 0, got " + std::to_string(dt));
  if (!(alpha >= 0.0)) ThrowInvalid(file, line, "alpha must be >= 0, got " + std::to_string(alpha));
  if (!(qc > 0.0)) ThrowInvalid(file, line, "Qc must be > 0, got " + std::to_string(qc));
}
}  // namespace internal

// A 3N×3N matrix made of a 3×3 grid of DIAGONAL N×N blocks: the shape of Φ, Q, Q⁻¹, Λ and Ω
// for N independent axes with stacked state [p(N); v(N); a(N)]. Stored as block(i, j) = the
// diagonal as an N-array; products cost O(N) instead of O(N³).
template <int N>
class AxisBlockMatrix {
 public:
  using Diag = Eigen::Array<double, N, 1>;
  using Dense = Eigen::Matrix<double, 3 * N, 3 * N>;
  using Vector = Eigen::Matrix<double, 3 * N, 1>;

  AxisBlockMatrix() {
    for (auto& b : blocks_) b.setZero();
  }

  Diag& block(int i, int j) { return blocks_[3 * i + j]; }
  const Diag& block(int i, int j) const { return blocks_[3 * i + j]; }

  // Sets axis `axis` from a 3×3 per-axis matrix.
  void SetAxis(int axis, const Eigen::Matrix3d& m) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) block(i, j)[axis] = m(i, j);
  }
  Eigen::Matrix3d Axis(int axis) const {
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = block(i, j)[axis];
    return m;
  }

  Dense ToDense() const {
    Dense d = Dense::Zero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) d.template block<N, N>(N * i, N * j).diagonal() = block(i, j);
    return d;
  }

  Vector operator*(const Vector& x) const {
    Vector y;
    for (int i = 0; i < 3; ++i) {
      y.template segment<N>(N * i) = (block(i, 0) * x.template segment<N>(0).array() +
                                      block(i, 1) * x.template segment<N>(N).array() +
                                      block(i, 2) * x.template segment<N>(2 * N).array())
                                         .matrix();
    }
    return y;
  }

  AxisBlockMatrix operator*(const AxisBlockMatrix& o) const {
    AxisBlockMatrix r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.block(i, j) =
            block(i, 0) * o.block(0, j) + block(i, 1) * o.block(1, j) + block(i, 2) * o.block(2, j);
    return r;
  }

 private:
  std::array<Diag, 9> blocks_;
};

// N independent Singer axes (per-axis Qc and α ≥ 0; α = 0 is WNOJ), stacked state
// [p(N); v(N); a(N)]. SE(3) uses SingerModel<6> with [ρ; φ] axis order; the 1D study N = 1.
template <int N>
class SingerModel {
 public:
  static constexpr int kAxes = N;
  static constexpr int kStateSize = 3 * N;
  using VecN = Eigen::Matrix<double, N, 1>;
  using Blocks = AxisBlockMatrix<N>;
  using Matrix = typename Blocks::Dense;

  SingerModel(const VecN& qc, const VecN& alpha) : qc_(qc), alpha_(alpha) {
    for (int i = 0; i < N; ++i)
      internal::CheckModelArguments(alpha[i], qc[i], 1.0, __FILE__, __LINE__);
  }
  // White noise on jerk on every axis.
  static SingerModel Wnoj(const VecN& qc) { return SingerModel(qc, VecN::Zero()); }

  const VecN& qc() const { return qc_; }
  const VecN& alpha() const { return alpha_; }

  // Structured (block-diagonal) forms; the dense ones below expand them.
  Blocks TransitionBlocks(double dt) const {
    Blocks b;
    ForEachAxis(dt, [&](int i, const SingerShape& s) {
      b.block(0, 0)[i] = 1.0;
      b.block(0, 1)[i] = dt;
      b.block(0, 2)[i] = dt * dt * s.g2;
      b.block(1, 1)[i] = 1.0;
      b.block(1, 2)[i] = dt * s.g1;
      b.block(2, 2)[i] = s.e;
    });
    return b;
  }
  Blocks CovarianceBlocks(double dt) const {
    Blocks b;
    ForEachAxis(dt, [&](int i, const SingerShape& s) { b.SetAxis(i, qc_[i] * Scaled(s, dt)); });
    return b;
  }
  Blocks InformationBlocks(double dt) const {
    Blocks b;
    ForEachAxis(dt, [&](int i, const SingerShape& s) {
      const Eigen::Matrix3d W = SqrtInformationFromShape(s, qc_[i], dt);
      b.SetAxis(i, W.transpose() * W);
    });
    return b;
  }
  Blocks SqrtInformationBlocks(double dt) const {
    Blocks b;
    ForEachAxis(dt, [&](int i, const SingerShape& s) {
      b.SetAxis(i, SqrtInformationFromShape(s, qc_[i], dt));
    });
    return b;
  }

  Matrix Transition(double dt) const { return TransitionBlocks(dt).ToDense(); }
  Matrix Covariance(double dt) const { return CovarianceBlocks(dt).ToDense(); }
  Matrix Information(double dt) const { return InformationBlocks(dt).ToDense(); }
  // Lower-block-triangular W with WᵀW = Q(Δt)⁻¹.
  Matrix SqrtInformation(double dt) const { return SqrtInformationBlocks(dt).ToDense(); }

  // Per-axis helpers shared with the interpolator: Φ and Q with Qc = 1 (Qc cancels in Λ, Ω).
  static Eigen::Matrix3d ShapeTransition(const SingerShape& s, double dt) {
    Eigen::Matrix3d P;
    P << 1.0, dt, dt * dt * s.g2, 0.0, 1.0, dt * s.g1, 0.0, 0.0, s.e;
    return P;
  }
  static Eigen::Matrix3d Scaled(const SingerShape& s, double dt) {
    const double d2 = dt * dt, d3 = d2 * dt;
    Eigen::Matrix3d Q;
    Q << s.q11 * d3 * d2, s.q12 * d2 * d2, s.q13 * d3,  //
        s.q12 * d2 * d2, s.q22 * d3, s.q23 * d2,        //
        s.q13 * d3, s.q23 * d2, s.q33 * dt;
    return Q;
  }
  static Eigen::Matrix3d SqrtInformationFromShape(const SingerShape& s, double qc, double dt);

  // Calls f(axis, shape(α_axis·dt)); axes with the α of the previous axis reuse its shape.
  template <typename F>
  void ForEachAxis(double dt, F&& f) const {
    if (!(dt > 0.0)) internal::ThrowInvalid(__FILE__, __LINE__, "time step must be > 0");
    SingerShape s{};
    for (int i = 0; i < N; ++i) {
      if (i == 0 || alpha_[i] != alpha_[i - 1]) s = EvaluateSingerShape(alpha_[i] * dt);
      f(i, s);
    }
  }

 private:
  VecN qc_;
  VecN alpha_;
};

// W = L⁻¹·D⁻¹/√Qc for q = LLᵀ: the Cholesky of the dimensionless q(x) is well conditioned
// (it does not see Δt), so W keeps full precision for tiny and huge Δt alike.
Eigen::Matrix3d SingerSqrtInformationFromShape(const SingerShape& s, double qc, double dt);

template <int N>
Eigen::Matrix3d SingerModel<N>::SqrtInformationFromShape(const SingerShape& s, double qc,
                                                         double dt) {
  return SingerSqrtInformationFromShape(s, qc, dt);
}

}  // namespace ctlio::gp
