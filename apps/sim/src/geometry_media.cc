// The parts of a Scene that are not solids (geometry.h): scattering media, ground cover, the
// ground's micro-relief, and the per-ray random draws they use.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "ctlio/sim/geometry.h"

namespace ctlio::sim {
namespace {

uint64_t SplitMix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

uint64_t Bits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof(b));
  return b;
}

// Exponentially distributed depth with mean `free_path` (inverse transform of a uniform draw).
double ExpDepth(double u, double free_path) { return -free_path * std::log1p(-u); }

// Value noise in [−1, 1]: uniform values at the nodes of a square lattice (hashed from the
// seed), blended with the C¹ smoothstep. Cheaper than waves and without a period.
double ValueNoise(uint64_t seed, double x, double y, double lattice) {
  const double a = x / lattice, b = y / lattice;
  const double fa = std::floor(a), fb = std::floor(b);
  const int64_t i = int64_t(fa), j = int64_t(fb);
  auto node = [&](int64_t di, int64_t dj) {
    const uint64_t h = SplitMix(SplitMix(seed ^ uint64_t(i + di)) ^ uint64_t(j + dj));
    return 2.0 * double(h >> 11) * 0x1.0p-53 - 1.0;
  };
  const double u = a - fa, v = b - fb;
  const double su = u * u * (3 - 2 * u), sv = v * v * (3 - 2 * v);
  return (node(0, 0) * (1 - su) + node(1, 0) * su) * (1 - sv) +
         (node(0, 1) * (1 - su) + node(1, 1) * su) * sv;
}

}  // namespace

double RayUniform(uint64_t seed, const Vec3& o, const Vec3& d, uint64_t salt) {
  uint64_t h = SplitMix(seed ^ (salt * 0xD1B54A32D192ED03ULL));
  for (int i = 0; i < 3; ++i) h = SplitMix(h ^ Bits(o[i]));
  for (int i = 0; i < 3; ++i) h = SplitMix(h ^ Bits(d[i]));
  return double(h >> 11) * 0x1.0p-53;
}

RayHit Scene::IntersectMedium(uint32_t index, const Vec3& o, const Vec3& d, const Vec3& inv_d,
                              double t_max) const {
  const Medium& m = media[index];
  double t0 = 0.0, t1 = t_max;
  if (m.box) {
    for (int i = 0; i < 3; ++i) {
      const double lo = m.centre[i] - m.radii[i], hi = m.centre[i] + m.radii[i];
      if (d[i] == 0.0) {
        if (o[i] < lo || o[i] > hi) return {};
        continue;
      }
      double a = (lo - o[i]) * inv_d[i], b = (hi - o[i]) * inv_d[i];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
  } else {
    // |(o − c + t·d) ⊘ radii|² = 1: a quadratic in t.
    const Vec3 oc = (o - m.centre).cwiseQuotient(m.radii), dd = d.cwiseQuotient(m.radii);
    const double a = dd.squaredNorm(), b = oc.dot(dd), c = oc.squaredNorm() - 1.0;
    const double disc = b * b - a * c;
    if (disc < 0.0) return {};
    const double root = std::sqrt(disc);
    t0 = std::max(t0, (-b - root) / a);
    t1 = std::min(t1, (-b + root) / a);
  }
  if (!(t0 < t1)) return {};
  const double s = ExpDepth(RayUniform(seed, o, d, index + 1), m.free_path);
  if (t0 + s >= t1 || t0 + s <= 0.0) return {};
  return {t0 + s, -d};
}

double Scene::Relief(double x, double y) const {
  return relief == 0.0 ? 0.0 : relief * ValueNoise(seed ^ 0x5E11EFULL, x, y, 0.6);
}

RayHit Scene::CastGround(const Vec3& o, const Vec3& d, double t_max) const {
  RayHit g;
  for (const double z : floors) {
    if (d.z() < 0.0 && o.z() > z) {
      const double t = (z - o.z()) / d.z();
      if (t < g.t) g = {t, Vec3(0, 0, 1)};
    }
  }
  for (const HeightField& f : fields) {
    const RayHit h = IntersectHeightField(f, o, d, std::min(t_max + 1.0, g.t));
    if (h.t < g.t) g = h;
  }
  if (!g.Valid() || d.z() >= -1e-6) return g.t < t_max ? g : RayHit{};
  const Vec3 p = o + g.t * d;
  const double dz = -d.z();
  const GroundCover* cover = nullptr;
  for (const GroundCover& c : covers) {
    if (p.x() >= c.x0 && p.x() <= c.x1 && p.y() >= c.y0 && p.y() <= c.y1) {
      cover = &c;
      break;
    }
  }
  // A surface raised by δz is met δz/|d_z| earlier along the ray (clamped at grazing rays);
  // under a cover the ground has its tussocks too (a finer lattice).
  const double dzr = Relief(p.x(), p.y());
  double t = g.t - std::clamp(dzr / dz, -0.5, 0.5);
  if (cover != nullptr) {
    const GroundCover& c = *cover;
    const double tussock =
        c.relief != 0.0 ? c.relief * ValueNoise(seed ^ 0x7A55ULL, p.x(), p.y(), 0.25) : 0.0;
    double tc = g.t - std::clamp((dzr + tussock) / dz, -0.5, 0.5);
    const double chord = c.height / dz;
    const double s = ExpDepth(RayUniform(seed, o, d, 0x6AA55ULL), c.free_path);
    if (s < chord) tc -= chord - s;
    // The return lies over the cover (at its edge, a ray entering the layer outside the
    // rectangle reaches the bare ground).
    const Vec3 q = o + tc * d;
    if (q.x() >= c.x0 && q.x() <= c.x1 && q.y() >= c.y0 && q.y() <= c.y1) t = tc;
  }
  if (!(t > 0.0)) t = g.t;
  g.t = t;
  return g.t < t_max ? g : RayHit{};
}

Vec3 Mover::At(double time) const {
  const double L = (b - a).norm();
  if (L <= 0.0) return a;
  const double s = std::fmod(std::max(speed * time + phase, 0.0), 2 * L);
  return a + (std::min(s, 2 * L - s) / L) * (b - a);
}

bool Scene::OnMover(const Vec3& p, double time) const {
  for (const Mover& m : movers) {
    const Vec3 base = m.At(time);
    if ((p - base).head<2>().norm() <= m.radius + 1e-3 && p.z() >= base.z() - 1e-3 &&
        p.z() <= base.z() + m.height + 1e-3)
      return true;
  }
  return false;
}

bool Scene::InMedium(const Vec3& p) const {
  for (const Medium& m : media) {
    const Vec3 e = (p - m.centre).cwiseQuotient(m.radii);
    if (m.box ? e.cwiseAbs().maxCoeff() <= 1.0 + 1e-9 : e.squaredNorm() <= 1.0 + 1e-9) return true;
  }
  // Within the relief (and the cover above it) of a floor or a height field.
  auto near_ground = [&](double ground) {
    double below = std::abs(relief) + 1e-6, above = below;
    for (const GroundCover& c : covers) {
      if (p.x() >= c.x0 && p.x() <= c.x1 && p.y() >= c.y0 && p.y() <= c.y1) {
        above += c.height + std::abs(c.relief);
        below += std::abs(c.relief);
        break;
      }
    }
    return (relief != 0.0 || !covers.empty()) && p.z() >= ground - below && p.z() <= ground + above;
  };
  for (const double z : floors)
    if (near_ground(z)) return true;
  for (const HeightField& f : fields) {
    const double h = f.Height(p.x(), p.y());
    if (!std::isnan(h) && near_ground(h)) return true;
  }
  return false;
}

}  // namespace ctlio::sim
