#include "ctlio/factors/gp/motion_model.h"

#include <cmath>
#include <cstddef>
#include <sstream>

namespace ctlio::gp {
namespace internal {

void ThrowInvalid(const char* file, int line, const std::string& what) {
  std::ostringstream os;
  os << file << ":" << line << ": " << what;
  throw std::runtime_error(os.str());
}

}  // namespace internal

namespace {

// Taylor coefficients c₀ … c₂₅ (x⁰ … x²⁵) of g1, g2 and q11 … q33, computed exactly (rational
// arithmetic, sympy) from the closed forms of SPEC §2 and rounded once to double. Truncation
// after x²⁵ leaves < 1e-17 relative error for x ≤ 1.25 (the largest dropped term of q33 is
// 2·(2x)²⁶/28!-like, ≈ 1e-18 there).
constexpr double kG1[] = {1,
                          -0.5,
                          0.16666666666666666,
                          -0.041666666666666664,
                          0.0083333333333333332,
                          -0.0013888888888888889,
                          0.00019841269841269841,
                          -2.4801587301587302e-05,
                          2.7557319223985893e-06,
                          -2.7557319223985888e-07,
                          2.505210838544172e-08,
                          -2.08767569878681e-09,
                          1.6059043836821613e-10,
                          -1.1470745597729725e-11,
                          7.6471637318198164e-13,
                          -4.7794773323873853e-14,
                          2.8114572543455206e-15,
                          -1.5619206968586225e-16,
                          8.2206352466243295e-18,
                          -4.1103176233121648e-19,
                          1.9572941063391263e-20,
                          -8.8967913924505741e-22,
                          3.8681701706306841e-23,
                          -1.6117375710961184e-24,
                          6.4469502843844736e-26,
                          -2.4795962632247976e-27};
constexpr double kG2[] = {0.5,
                          -0.16666666666666666,
                          0.041666666666666664,
                          -0.0083333333333333332,
                          0.0013888888888888889,
                          -0.00019841269841269841,
                          2.4801587301587302e-05,
                          -2.7557319223985893e-06,
                          2.7557319223985888e-07,
                          -2.505210838544172e-08,
                          2.08767569878681e-09,
                          -1.6059043836821613e-10,
                          1.1470745597729725e-11,
                          -7.6471637318198164e-13,
                          4.7794773323873853e-14,
                          -2.8114572543455206e-15,
                          1.5619206968586225e-16,
                          -8.2206352466243295e-18,
                          4.1103176233121648e-19,
                          -1.9572941063391263e-20,
                          8.8967913924505741e-22,
                          -3.8681701706306841e-23,
                          1.6117375710961184e-24,
                          -6.4469502843844736e-26,
                          2.4795962632247976e-27,
                          -9.183689863795546e-29};
constexpr double kQ11[] = {
    0.050000000000000003,    -0.027777777777777776,   0.0099206349206349201,
    -0.0027777777777777779,  0.0006558641975308642,   -0.00013558201058201059,
    2.5102212602212603e-05,  -4.2254556143445033e-06, 6.5360308415863968e-07,
    -9.3647167059865471e-08, 1.2506171567018128e-08,  -1.5646096995303344e-09,
    1.8415607307414029e-10,  -2.0466784043356649e-11, 2.1546778219517165e-12,
    -2.1548257933861558e-13, 2.0522894184961894e-14,  -1.8657532403439238e-15,
    1.6224103683529112e-16,  -1.3520157319394055e-17, 1.0816155511486551e-18,
    -8.3201315262824881e-20, 6.1630649816838115e-21,  -4.4021909781736977e-22,
    3.0359943887888219e-23,  -2.0239964703118551e-24};
constexpr double kQ12[] = {0.125,
                           -0.083333333333333329,
                           0.034722222222222224,
                           -0.011111111111111112,
                           0.0029513888888888888,
                           -0.00067791005291005296,
                           0.00013806216931216931,
                           -2.535273368606702e-05,
                           4.2484200470311584e-06,
                           -6.555301694190583e-07,
                           9.3796286752635963e-08,
                           -1.2516877596242676e-08,
                           1.5653266211301926e-09,
                           -1.8420105639020982e-10,
                           2.0469439308541306e-11,
                           -2.1548257933861559e-12,
                           2.1549038894209988e-13,
                           -2.0523285643783161e-14,
                           1.8657719236058477e-15,
                           -1.6224188783272867e-16,
                           1.3520194389358189e-17,
                           -1.0816170984167235e-18,
                           8.320137725273146e-20,
                           -6.1630673694431764e-21,
                           4.4021918637437917e-22,
                           -3.0359947054677823e-23};
constexpr double kQ13[] = {
    0.16666666666666666,     -0.16666666666666666,    0.09166666666666666,
    -0.036111111111111108,   0.011309523809523809,    -0.002976190476190476,
    0.00068066578483245153,  -0.00013833774250440918, 2.5377785794452461e-05,
    -4.2505077227299451e-06, 6.5569075985742654e-07,  -9.3807757498233694e-08,
    1.2517642312615858e-08,  -1.5653744159035164e-09, 1.8420386784746418e-10,
    -2.0469595500610993e-11, 2.1548340140214024e-12,  -2.154907999738622e-13,
    2.0523305216724225e-14,  -1.865772813284987e-15,  1.6224192651443036e-16,
    -1.352019600109576e-17,  1.0816171628862263e-18,  -8.320137973232772e-20,
    6.1630674612800752e-21,  -4.4021918965426834e-22};
constexpr double kQ22[] = {0.33333333333333331,    -0.25,
                           0.11666666666666667,    -0.041666666666666664,
                           0.012301587301587301,   -0.0031250000000000002,
                           0.00069995590828924161, -0.00014054232804232804,
                           2.5603254769921436e-05, -4.2713844797178134e-06,
                           6.5745725467947692e-07, -9.3945406445406441e-08,
                           1.2527583625467223e-08, -1.5660435427300506e-09,
                           1.8424603970627936e-10, -2.0472094573725967e-11,
                           2.1549737648205952e-12, -2.1549819854558418e-13,
                           2.0523677102604429e-14, -1.8657906068677719e-15,
                           1.6224273883016619e-16, -1.3520231459322325e-17,
                           1.0816186456847918e-18, -8.3201439242638038e-20,
                           6.1630697572025413e-21, -4.4021927493138858e-22};
constexpr double kQ23[] = {0.5,
                           -0.5,
                           0.29166666666666669,
                           -0.125,
                           0.043055555555555555,
                           -0.012500000000000001,
                           0.0031498015873015874,
                           -0.00070271164021164017,
                           0.00014081790123456791,
                           -2.5628306878306877e-05,
                           4.2734721554166002e-06,
                           -6.5761784511784515e-07,
                           9.3956877191004172e-08,
                           -1.2528348341840405e-08,
                           1.5660913375033746e-09,
                           -1.8424885116353371e-10,
                           2.0472250765795654e-11,
                           -2.1549819854558417e-12,
                           2.154986095773465e-13,
                           -2.0523696675545493e-14,
                           1.8657914965469113e-15,
                           -1.6224277751186791e-16,
                           1.3520233071059896e-17,
                           -1.0816187101542946e-18,
                           8.3201441722234299e-20,
                           -6.1630698490394394e-21};
constexpr double kQ33[] = {1,
                           -1,
                           0.66666666666666663,
                           -0.33333333333333331,
                           0.13333333333333333,
                           -0.044444444444444446,
                           0.012698412698412698,
                           -0.0031746031746031746,
                           0.00070546737213403885,
                           -0.00014109347442680775,
                           2.5653358986692322e-05,
                           -4.2755598311153869e-06,
                           6.5777843555621328e-07,
                           -9.3968347936601903e-08,
                           1.2529113058213587e-08,
                           -1.5661391322766984e-09,
                           1.8425166262078804e-10,
                           -2.0472406957865337e-11,
                           2.1549902060910882e-12,
                           -2.1549902060910883e-13,
                           2.0523716248486557e-14,
                           -1.8657923862260506e-15,
                           1.6224281619356961e-16,
                           -1.3520234682797467e-17,
                           1.0816187746237974e-18,
                           -8.3201444201830571e-20};

template <std::size_t K>
inline double Horner(double x, const double (&c)[K]) {
  double s = c[K - 1];
  for (std::size_t k = K - 1; k-- > 0;) s = s * x + c[k];
  return s;
}

}  // namespace

SingerShape SingerShapeSeries(double x) {
  SingerShape s;
  s.e = std::exp(-x);
  s.g1 = Horner(x, kG1);
  s.g2 = Horner(x, kG2);
  s.q11 = Horner(x, kQ11);
  s.q12 = Horner(x, kQ12);
  s.q13 = Horner(x, kQ13);
  s.q22 = Horner(x, kQ22);
  s.q23 = Horner(x, kQ23);
  s.q33 = Horner(x, kQ33);
  return s;
}

SingerShape SingerShapeClosedForm(double x) {
  // 1 − e^{−x} and 1 − e^{−2x} through expm1 so that they keep full precision; the remaining
  // cancellation (q11's 2x − 2x² + (2/3)x³ against 1 − e^{−2x} − 4xe^{−x}) costs < 3e-15
  // relative for x ≥ kSingerSeriesSwitch.
  SingerShape s;
  const double E = std::exp(-x);
  const double omE = -std::expm1(-x);
  const double omE2 = -std::expm1(-2.0 * x);
  const double x2 = x * x, x3 = x2 * x, x4 = x2 * x2, x5 = x4 * x;
  s.e = E;
  s.g1 = omE / x;
  s.g2 = (x - omE) / x2;
  s.q11 = (omE2 + 2.0 * x + (2.0 / 3.0) * x3 - 2.0 * x2 - 4.0 * x * E) / (2.0 * x5);
  // E2 + 1 − 2E = (1 − E)².
  s.q12 = (omE * omE + 2.0 * x * E - 2.0 * x + x2) / (2.0 * x4);
  s.q13 = (omE2 - 2.0 * x * E) / (2.0 * x3);
  s.q22 = (4.0 * E - 3.0 - E * E + 2.0 * x) / (2.0 * x3);
  s.q23 = omE * omE / (2.0 * x2);
  s.q33 = omE2 / (2.0 * x);
  return s;
}

SingerShape EvaluateSingerShape(double x) {
  if (x == 0.0) {
    // WNOJ, exactly (the series' constant terms, written out).
    return SingerShape{1.0, 1.0, 0.5, 1.0 / 20, 1.0 / 8, 1.0 / 6, 1.0 / 3, 1.0 / 2, 1.0};
  }
  return x < kSingerSeriesSwitch ? SingerShapeSeries(x) : SingerShapeClosedForm(x);
}

Eigen::Matrix3d SingerSqrtInformationFromShape(const SingerShape& s, double qc, double dt) {
  // Cholesky q = LLᵀ of the dimensionless covariance, then W = L⁻¹·D⁻¹/√Qc.
  const double l11 = std::sqrt(s.q11);
  const double l21 = s.q12 / l11;
  const double l31 = s.q13 / l11;
  const double l22 = std::sqrt(s.q22 - l21 * l21);
  const double l32 = (s.q23 - l31 * l21) / l22;
  const double l33 = std::sqrt(s.q33 - l31 * l31 - l32 * l32);
  const double w11 = 1.0 / l11, w22 = 1.0 / l22, w33 = 1.0 / l33;
  const double w21 = -l21 * w11 * w22;
  const double w32 = -l32 * w22 * w33;
  const double w31 = -(l31 * w11 + l32 * w21) * w33;
  const double sd = std::sqrt(dt);
  const double c = 1.0 / std::sqrt(qc);
  const double d3 = c / sd, d2 = d3 / dt, d1 = d2 / dt;  // D⁻¹/√Qc
  Eigen::Matrix3d W;
  W << w11 * d1, 0.0, 0.0,      //
      w21 * d1, w22 * d2, 0.0,  //
      w31 * d1, w32 * d2, w33 * d3;
  return W;
}

Eigen::Matrix3d SingerTransition(double alpha, double dt) {
  internal::CheckModelArguments(alpha, 1.0, dt, __FILE__, __LINE__);
  return SingerModel<1>::ShapeTransition(EvaluateSingerShape(alpha * dt), dt);
}

Eigen::Matrix3d SingerCovariance(double alpha, double qc, double dt) {
  internal::CheckModelArguments(alpha, qc, dt, __FILE__, __LINE__);
  return qc * SingerModel<1>::Scaled(EvaluateSingerShape(alpha * dt), dt);
}

Eigen::Matrix3d SingerSqrtInformation(double alpha, double qc, double dt) {
  internal::CheckModelArguments(alpha, qc, dt, __FILE__, __LINE__);
  return SingerSqrtInformationFromShape(EvaluateSingerShape(alpha * dt), qc, dt);
}

Eigen::Matrix3d SingerInformation(double alpha, double qc, double dt) {
  const Eigen::Matrix3d W = SingerSqrtInformation(alpha, qc, dt);
  return W.transpose() * W;
}

Eigen::Matrix2d WnoaTransition(double dt) {
  internal::CheckModelArguments(0.0, 1.0, dt, __FILE__, __LINE__);
  Eigen::Matrix2d P;
  P << 1.0, dt, 0.0, 1.0;
  return P;
}

Eigen::Matrix2d WnoaCovariance(double qc, double dt) {
  internal::CheckModelArguments(0.0, qc, dt, __FILE__, __LINE__);
  Eigen::Matrix2d Q;
  Q << dt * dt * dt / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt;
  return qc * Q;
}

Eigen::Matrix2d WnoaInformation(double qc, double dt) {
  internal::CheckModelArguments(0.0, qc, dt, __FILE__, __LINE__);
  Eigen::Matrix2d I;
  I << 12.0 / (dt * dt * dt), -6.0 / (dt * dt), -6.0 / (dt * dt), 4.0 / dt;
  return I / qc;
}

Eigen::Matrix2d WnoaSqrtInformation(double qc, double dt) {
  internal::CheckModelArguments(0.0, qc, dt, __FILE__, __LINE__);
  // q = [[1/3, 1/2], [1/2, 1]] = LLᵀ with L = [[1/√3, 0], [√3/2, 1/2]]; W = L⁻¹·D⁻¹/√Qc,
  // D = diag(Δt^{3/2}, Δt^{1/2}).
  const double s3 = std::sqrt(3.0);
  const double c = 1.0 / std::sqrt(qc * dt);
  Eigen::Matrix2d W;
  W << s3 * c / dt, 0.0, -3.0 * c / dt, 2.0 * c;
  return W;
}

}  // namespace ctlio::gp
