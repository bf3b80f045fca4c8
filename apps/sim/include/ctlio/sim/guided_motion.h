// Motion guided along a world's path (docs/user-guide/simulator.md).
//
// A world gives a closed centreline at floor level: a polygon with rounded corners, resampled at
// a uniform arc-length spacing Δ and used as the control points of a closed uniform cubic
// B-spline c(u) (C², so the IMU's specific force is continuous). The carrier moves along it at
// arc length s(t) ≈ Δ·u:
//
//   τ = t − start_s (0 before the start: stationary),
//   e(τ) = 10x³ − 15x⁴ + 6x⁵, x = min(τ/ramp_s, 1)                (C² start ramp),
//   s(τ) = s₀ + v₀·∫e + (a_v/ω_v)(1 − cos ω_v τ)·e(τ)              (ṡ ≥ 0 when a_v ≤ v₀),
//   p(t) = c(u) + R_z(ψ_c)·[0, ℓ(τ), h + b(τ)],   C(t) = R_z(ψ_c + ψ(τ))·R_y(θ(τ))·R_x(φ(τ)),
//
// with ψ_c the heading of the centreline tangent, h the sensor height above the floor and every
// oscillation ℓ (lateral sway), b (vertical bob), ψ (head turns, two tones), θ (pitch), φ (roll)
// of the form e(τ)·A·sin(2πfτ). The body twist [v; ω] and its rate follow exactly from p, ṗ, p̈,
// C, Ċ, C̈ (computed by second-order forward differentiation): ω^ = CᵀĊ, v = Cᵀṗ,
// ω̇^ = ĊᵀĊ + CᵀC̈, v̇ = Ċᵀṗ + Cᵀp̈.
#pragma once

#include <functional>
#include <vector>

#include "ctlio/manifolds/se3.h"

namespace ctlio::sim {

struct Oscillation {
  double amplitude = 0.0;  // m or rad
  double frequency = 0.0;  // Hz
};

struct GuideProfile {
  double start_fraction = 0.0;  // s₀ as a fraction of the world's start range
  double speed = 0.0;           // v₀ [m/s]
  Oscillation speed_wave;       // a_v [m/s] at f_v
  double ramp_s = 1.0;          // duration of the start ramp [s]
  double height = 1.5;          // sensor (IMU) height above the path's floor [m]
  Oscillation lateral, vertical, yaw_slow, yaw_fast, pitch, roll;
};

// Closed uniform cubic B-spline through (approximately) a rounded polygon.
class Path {
 public:
  Path() = default;
  // `corners`: polygon vertices (closed; z = floor height, interpolated linearly along a side,
  // constant through a rounded corner); `radius`: corner rounding in xy; `spacing`: Δ.
  // `floor`, when given, replaces z by floor(x, y) (terrain following).
  Path(const std::vector<Vec3>& corners, double radius, double spacing,
       const std::function<double(double, double)>& floor = nullptr);
  const std::vector<Vec3>& ControlPoints() const { return points_; }
  double Spacing() const { return spacing_; }
  double Length() const { return spacing_ * double(points_.size()); }
  // c(s/Δ) and its first and second derivatives with respect to s.
  void Evaluate(double s, Vec3* c, Vec3* dc, Vec3* ddc, Vec3* dddc = nullptr) const;

 private:
  std::vector<Vec3> points_;
  double spacing_ = 1.0;
};

struct PoseRates {
  SE3 pose;                        // T_wb
  Vec6 twist = Vec6::Zero();       // [v; ω], body frame
  Vec6 twist_rate = Vec6::Zero();  // d/dt [v; ω]
};

// The guided pose at time t [s since the sequence start]; `s0` = start arc length.
PoseRates EvaluateGuide(const Path& path, const GuideProfile& g, double start_s, double s0,
                        double t);

// Largest carrier speed of a profile (v₀ + a_v).
inline double PeakSpeed(const GuideProfile& g) { return g.speed + g.speed_wave.amplitude; }

}  // namespace ctlio::sim
