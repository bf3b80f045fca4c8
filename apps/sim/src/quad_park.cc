#include "quad_park.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "ctlio/sim/random_draw.h"
#include "ctlio/sim/worlds.h"
#include "world_content.h"

namespace ctlio::sim {
namespace {

double DistanceToSegment(double x, double y, const Vec3& a, const Vec3& b) {
  const double dx = b.x() - a.x(), dy = b.y() - a.y(), l2 = dx * dx + dy * dy;
  const double t =
      l2 > 0.0 ? std::clamp(((x - a.x()) * dx + (y - a.y()) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(x - a.x() - t * dx, y - a.y() - t * dy);
}

// Clipped box hedges are dense: returns from the first ≈ 0.1 m (the park's tall hedges: 0.35 m).
// With the tall hedges' free path, or with more trees and bushes, the park's sweeps leave the
// real sweeps' band of scattered fraction (docs/experiments/worlds-geometry.md, "The open park").
constexpr double kClippedHedgeFreePath = 0.1;

}  // namespace

void FurnishPark(Scene& s, const Path& path, const ParkBounds& park, uint64_t seed) {
  std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(WorldKind::kQuad), 0x9a7cu};
  std::mt19937_64 rng(seq);
  auto U = [&](double lo, double hi) { return Uniform(rng, lo, hi); };
  const std::vector<Mover> lanes = s.movers;
  // Horizontal room at (x, y): to the path, and to a walking person's lane less 0.5 m (their body
  // and a step aside).
  auto room = [&](double x, double y) {
    double d = content::DistanceToPath(path, x, y);
    for (const Mover& m : lanes) d = std::min(d, DistanceToSegment(x, y, m.a, m.b) - 0.5);
    return d;
  };

  // The rim on the south, east and north sides, in runs of 12–24 m: a stone wall 2.8–4.5 m high
  // just outside the lawn with buttresses every 10–16 m, and behind a quarter of the runs a
  // building of 2–3 storeys facing the park.
  struct Side {
    Vec3 a, e, n;  // start corner, along, outwards
    double length;
    int facade;  // the building face towards the park (content::AddBuilding's bits)
  };
  const double lx = park.x1 - park.x0, ly = park.y1 - park.y0;
  const Side sides[3] = {{Vec3(park.x0, park.y0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), lx, 1 << 2},
                         {Vec3(park.x1, park.y0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), ly, 1 << 3},
                         {Vec3(park.x1, park.y1, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), lx, 1 << 0}};
  for (const Side& side : sides) {
    auto at = [&](double u, double w) { return side.a + u * side.e + w * side.n; };
    for (double u = -4.0; u < side.length + 4.0;) {
      const double len = std::min(U(12, 24), side.length + 4.0 - u);
      const double h = U(2.8, 4.5), w0 = U(1.5, 2.2);
      s.boxes.push_back(Box::Spanning(at(u, w0), at(u + len, w0 + 0.9) + Vec3(0, 0, h)));
      for (double b = u + U(1, 4); b < u + len - 0.8; b += U(10, 16))
        s.boxes.push_back(Box::Spanning(at(b, w0 - 0.6), at(b + 0.7, w0) + Vec3(0, 0, 0.75 * h)));
      if (U(0, 1) < 0.25) {
        const double wb = U(5, 12), depth = U(9, 13);
        const Vec3 p = at(u, wb), q = at(u + len, wb + depth);
        const int storeys = 2 + int(U(0, 2));
        content::AddBuilding(s, rng, p.cwiseMin(q), p.cwiseMax(q), storeys, 3.5 * U(0.95, 1.05),
                             side.facade, content::CollegeFacadeStyle(rng));
      }
      u += len;
    }
  }

  // Along the path in the park, every 16–26 m on either side: a lamp post, a bench or a bin; and
  // every 12–24 m on straight stretches a clipped low hedge 2.4–3.2 m off the path (its edge).
  const std::vector<Vec3>& q = path.ControlPoints();  // Δ = 0.5 m apart
  const int n = int(q.size());
  auto tangent = [&](int i) { return (q[(i + 1) % n] - q[(i + n - 1) % n]).normalized(); };
  auto in_park = [&](const Vec3& p) { return p.x() > park.x0 + 5.0; };
  for (int i = int(U(10, 30)); i < n; i += int(U(32, 52))) {
    const Vec3 t = tangent(i), across = (U(0, 1) < 0.5 ? 1.0 : -1.0) * Vec3(-t.y(), t.x(), 0);
    const double kind = U(0, 1);
    if (!in_park(q[i])) continue;
    const Vec3 ground(q[i].x(), q[i].y(), 0.0);
    if (kind < 0.45) {
      const Vec3 b = ground + 1.8 * across;
      if (room(b.x(), b.y()) > 1.7) content::AddPole(s, rng, b);
    } else if (kind < 0.75) {
      const Vec3 b = ground + 2.2 * across;
      if (room(b.x(), b.y()) > 2.1) content::AddBench(s, b, std::abs(t.x()) > std::abs(t.y()));
    } else {
      const Vec3 b = ground + 1.5 * across;
      if (room(b.x(), b.y()) > 1.4) s.cylinders.push_back({b, 0.28, 0.95});
    }
  }
  for (int i = int(U(0, 20)); i < n; i += int(U(24, 48))) {
    const Vec3 t = tangent(i), across = (U(0, 1) < 0.5 ? 1.0 : -1.0) * Vec3(-t.y(), t.x(), 0);
    const double off = U(2.4, 3.2), len = U(5, 12), h = U(0.5, 0.9);
    if (!in_park(q[i]) || std::max(std::abs(t.x()), std::abs(t.y())) < 0.999) continue;
    const Vec3 ground(q[i].x(), q[i].y(), 0.0);
    bool clear = true;
    for (int k = 0; k <= 6 && clear; ++k) {
      const Vec3 c = ground + (k / 6.0) * len * t + (off + 0.3) * across;
      clear = room(c.x(), c.y()) > off - 0.2;
    }
    if (clear) {
      content::AddHedge(s, ground + off * across, ground + len * t + (off + 0.6) * across, h,
                        kClippedHedgeFreePath);
    }
  }

  // A mound in the lawn, like the one in the garden next to Newer College's quad (the dataset's
  // sequence 07, "parkland mound"): a smooth hill H·cos²(πr/2R), its foot clear of the path.
  const double R = U(11, 15), H = U(4, 6.5);
  const double cx = 0.5 * (park.x0 + park.x1) + U(-8, 8);
  const double cy = 0.5 * (park.y0 + park.y1) + U(-8, 8);
  if (content::DistanceToPath(path, cx, cy) > R + 4.0) {
    HeightField f;
    f.cell = 1.0;
    f.nx = f.ny = 2 * int(std::ceil(R));
    f.x0 = cx - 0.5 * f.nx;
    f.y0 = cy - 0.5 * f.ny;
    f.z.resize(size_t(f.nx + 1) * size_t(f.ny + 1));
    for (int j = 0; j <= f.ny; ++j) {
      for (int i = 0; i <= f.nx; ++i) {
        const double r = std::hypot(f.x0 + i - cx, f.y0 + j - cy);
        const double c = r < R ? std::cos(0.5 * M_PI * r / R) : 0.0;
        // Beyond the foot the field sinks just below the lawn, which then shows.
        f.z[size_t(j) * size_t(f.nx + 1) + size_t(i)] = r < R ? H * c * c : -0.05;
      }
    }
    f.UpdateTop();
    s.fields.push_back(std::move(f));
  }
}

}  // namespace ctlio::sim
