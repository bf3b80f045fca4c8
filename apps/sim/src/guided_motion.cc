#include "ctlio/sim/guided_motion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ctlio::sim {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
using Vec2 = Eigen::Vector2d;

// A function of time with its first two derivatives (second-order forward differentiation).
struct D2 {
  double v = 0.0, d = 0.0, dd = 0.0;
};
D2 operator+(D2 a, D2 b) { return {a.v + b.v, a.d + b.d, a.dd + b.dd}; }
D2 operator-(D2 a, D2 b) { return {a.v - b.v, a.d - b.d, a.dd - b.dd}; }
D2 operator*(double k, D2 a) { return {k * a.v, k * a.d, k * a.dd}; }
D2 operator*(D2 a, D2 b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd};
}
D2 Sin(D2 a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {s, c * a.d, c * a.dd - s * a.d * a.d};
}
D2 Cos(D2 a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {c, -s * a.d, -s * a.dd - c * a.d * a.d};
}
// atan2(y, x): ψ̇ = (x ẏ − y ẋ)/(x² + y²), differentiated once more by the quotient rule.
D2 Atan2(D2 y, D2 x) {
  const double n = x.v * y.d - y.v * x.d, q = x.v * x.v + y.v * y.v;
  const double dn = x.v * y.dd - y.v * x.dd, dq = 2 * (x.v * x.d + y.v * y.d);
  return {std::atan2(y.v, x.v), n / q, (dn * q - n * dq) / (q * q)};
}

// A rotation matrix with its first two time derivatives.
struct M2 {
  Mat3 v, d, dd;
};
M2 operator*(const M2& a, const M2& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd};
}
// Elementary rotation about `axis` by angle a.
M2 AxisRotation(int axis, D2 a) {
  const D2 c = Cos(a), s = Sin(a);
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  M2 m{Mat3::Identity(), Mat3::Zero(), Mat3::Zero()};
  const double* cp[3] = {&c.v, &c.d, &c.dd};
  const double* sp[3] = {&s.v, &s.d, &s.dd};
  Mat3* out[3] = {&m.v, &m.d, &m.dd};
  for (int k = 0; k < 3; ++k) {
    (*out[k])(i, i) = (*out[k])(j, j) = *cp[k];
    (*out[k])(j, i) = *sp[k];
    (*out[k])(i, j) = -*sp[k];
  }
  return m;
}

// e(τ)·A·sin(2πfτ).
D2 Wave(const Oscillation& o, D2 tau, D2 env) {
  return env * (o.amplitude * Sin(kTwoPi * o.frequency * tau));
}

Vec2 Xy(const Vec3& p) { return p.head<2>(); }

}  // namespace

Path::Path(const std::vector<Vec3>& corners, double radius, double spacing,
           const std::function<double(double, double)>& floor) {
  const size_t n = corners.size();
  if (n < 3 || spacing <= 0.0) throw std::runtime_error("Path: need ≥ 3 corners and Δ > 0");
  std::vector<Vec2> u(n);  // direction of side k → k+1
  for (size_t k = 0; k < n; ++k) u[k] = (Xy(corners[(k + 1) % n]) - Xy(corners[k])).normalized();
  std::vector<double> tangent(n);  // R·tan(θ/2) at corner k
  for (size_t k = 0; k < n; ++k) {
    const Vec2 a = u[(k + n - 1) % n], b = u[k];
    const double theta = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    tangent[k] = radius * std::tan(0.5 * theta);
  }
  std::vector<Vec3> dense;
  const double step = 0.02;
  for (size_t k = 0; k < n; ++k) {
    const Vec3 &A = corners[k], &B = corners[(k + 1) % n];
    const double len = (Xy(B) - Xy(A)).norm();
    if (tangent[k] + tangent[(k + 1) % n] > len) {
      throw std::runtime_error("Path: corner radius too large for a side");
    }
    // Straight part, z linear along the side.
    for (double a = tangent[k]; a < len - tangent[(k + 1) % n]; a += step) {
      Vec3 p;
      p << Xy(A) + a * u[k], A.z() + (B.z() - A.z()) * a / len;
      dense.push_back(p);
    }
    // Arc at B from the direction u[k] to u[k+1].
    const Vec2 ui = u[k], uo = u[(k + 1) % n];
    const double cross = ui.x() * uo.y() - ui.y() * uo.x();
    const double theta = std::acos(std::clamp(ui.dot(uo), -1.0, 1.0));
    if (tangent[(k + 1) % n] <= 0.0 || theta < 1e-9) continue;
    const double side = cross > 0 ? 1.0 : -1.0;
    const Vec2 normal = side * Vec2(-ui.y(), ui.x());
    const Vec2 centre = Xy(B) - tangent[(k + 1) % n] * ui + radius * normal;
    const Vec2 r0 = -radius * normal;
    const int m = std::max(2, int(std::ceil(radius * theta / step)));
    for (int i = 0; i < m; ++i) {
      const double phi = side * theta * i / m;
      const Vec2 r(std::cos(phi) * r0.x() - std::sin(phi) * r0.y(),
                   std::sin(phi) * r0.x() + std::cos(phi) * r0.y());
      Vec3 p;
      p << centre + r, B.z();
      dense.push_back(p);
    }
  }
  if (floor) {
    for (Vec3& p : dense) p.z() = floor(p.x(), p.y());
  }
  // Resample at a uniform arc length that closes the loop exactly.
  std::vector<double> arc(dense.size() + 1, 0.0);
  for (size_t i = 0; i < dense.size(); ++i) {
    arc[i + 1] = arc[i] + (dense[(i + 1) % dense.size()] - dense[i]).norm();
  }
  const size_t count = std::max<size_t>(4, size_t(std::llround(arc.back() / spacing)));
  spacing_ = arc.back() / double(count);
  size_t j = 0;
  for (size_t i = 0; i < count; ++i) {
    const double s = spacing_ * double(i);
    while (arc[j + 1] < s) ++j;
    const double f = (s - arc[j]) / std::max(arc[j + 1] - arc[j], 1e-15);
    points_.push_back((1 - f) * dense[j] + f * dense[(j + 1) % dense.size()]);
  }
}

void Path::Evaluate(double s, Vec3* c, Vec3* dc, Vec3* ddc, Vec3* dddc) const {
  const long n = long(points_.size());
  const double u = s / spacing_, fl = std::floor(u), w = u - fl;
  const long i = ((long(fl) % n) + n) % n;
  const Vec3& p0 = points_[size_t((i + n - 1) % n)];
  const Vec3& p1 = points_[size_t(i)];
  const Vec3& p2 = points_[size_t((i + 1) % n)];
  const Vec3& p3 = points_[size_t((i + 2) % n)];
  const double w2 = w * w, w3 = w2 * w, h = 1.0 / spacing_;
  *c = ((1 - w) * (1 - w) * (1 - w) * p0 + (3 * w3 - 6 * w2 + 4) * p1 +
        (-3 * w3 + 3 * w2 + 3 * w + 1) * p2 + w3 * p3) /
       6.0;
  *dc = h * (-0.5 * (1 - w) * (1 - w) * p0 + (1.5 * w2 - 2 * w) * p1 + (-1.5 * w2 + w + 0.5) * p2 +
             0.5 * w2 * p3);
  *ddc = h * h * ((1 - w) * p0 + (3 * w - 2) * p1 + (1 - 3 * w) * p2 + w * p3);
  if (dddc) *dddc = h * h * h * (-p0 + 3 * p1 - 3 * p2 + p3);
}

PoseRates EvaluateGuide(const Path& path, const GuideProfile& g, double start_s, double s0,
                        double t) {
  const D2 tau = t > start_s ? D2{t - start_s, 1.0, 0.0} : D2{};
  // Start ramp e(τ) and its integral.
  const double ramp = std::max(g.ramp_s, 1e-9);
  D2 env, integral;
  if (tau.v < ramp) {
    const D2 x = (1.0 / ramp) * tau, x2 = x * x, x3 = x2 * x;
    env = x3 * (D2{10, 0, 0} - 15.0 * x + 6.0 * x2);
    integral = ramp * (x3 * x * (D2{2.5, 0, 0} - 3.0 * x + x2));
  } else {
    env = {1.0, 0.0, 0.0};
    integral = tau - D2{0.5 * ramp, 0, 0};
  }
  D2 s = D2{s0, 0, 0} + g.speed * integral;
  if (g.speed_wave.amplitude != 0.0) {
    const double w = kTwoPi * g.speed_wave.frequency;
    s = s + (g.speed_wave.amplitude / w) * ((D2{1, 0, 0} - Cos(w * tau)) * env);
  }
  // Centreline and its tangent as functions of time (chain rule through s(t)).
  Vec3 c, cs, css, csss;
  path.Evaluate(s.v, &c, &cs, &css, &csss);
  const double sd = s.d, sdd = s.dd;
  const Vec3 c_d = cs * sd, c_dd = css * sd * sd + cs * sdd;
  const Vec3 tan_d = css * sd, tan_dd = csss * sd * sd + css * sdd;
  const D2 psi_c = Atan2({cs.y(), tan_d.y(), tan_dd.y()}, {cs.x(), tan_d.x(), tan_dd.x()});

  const D2 lateral = Wave(g.lateral, tau, env);
  const D2 up = D2{g.height, 0, 0} + Wave(g.vertical, tau, env);
  const D2 cp = Cos(psi_c), sp = Sin(psi_c);
  const D2 px = D2{c.x(), c_d.x(), c_dd.x()} - sp * lateral;
  const D2 py = D2{c.y(), c_d.y(), c_dd.y()} + cp * lateral;
  const D2 pz = D2{c.z(), c_d.z(), c_dd.z()} + up;

  const D2 yaw = psi_c + Wave(g.yaw_slow, tau, env) + Wave(g.yaw_fast, tau, env);
  const M2 C = AxisRotation(2, yaw) * AxisRotation(1, Wave(g.pitch, tau, env)) *
               AxisRotation(0, Wave(g.roll, tau, env));
  const Vec3 p(px.v, py.v, pz.v), pd(px.d, py.d, pz.d), pdd(px.dd, py.dd, pz.dd);

  PoseRates out;
  out.pose = SE3(C.v, p);
  const Mat3 Ct = C.v.transpose();
  out.twist << Ct * pd, so3::Vee(Ct * C.d);
  out.twist_rate << C.d.transpose() * pd + Ct * pdd, so3::Vee(C.d.transpose() * C.d + Ct * C.dd);
  return out;
}

}  // namespace ctlio::sim
