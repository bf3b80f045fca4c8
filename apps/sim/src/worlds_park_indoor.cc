// The park and the multi-level indoor world (parameters documented in worlds.h).
#include <algorithm>
#include <cmath>

#include "ctlio/sim/random_draw.h"
#include "ctlio/sim/worlds.h"

namespace ctlio::sim {
namespace {

// Horizontal distance from (x, y) to the nearest control point of the path.
double DistanceToPath(const Path& path, double x, double y) {
  double d2 = 1e300;
  for (const Vec3& q : path.ControlPoints()) {
    d2 = std::min(d2, (q.x() - x) * (q.x() - x) + (q.y() - y) * (q.y() - y));
  }
  return std::sqrt(d2);
}

}  // namespace

World BuildParkWorld(const ParkParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kPark);
  // Ground: four plane waves A·sin(k·x + φ) with random heading and wavelength.
  std::array<Vec3, 4> waves;  // kx, ky, φ
  for (Vec3& w : waves) {
    const double heading = Uniform(rng, 0, M_PI);
    const double k = 2 * M_PI / Uniform(rng, p.hill_wavelength.lo, p.hill_wavelength.hi);
    w = Vec3(k * std::cos(heading), k * std::sin(heading), Uniform(rng, 0, 2 * M_PI));
  }
  HeightField f;
  f.cell = p.cell;
  f.nx = f.ny = int(std::ceil(2 * p.extent / p.cell));
  f.x0 = f.y0 = -p.extent;
  f.z.resize(size_t(f.nx + 1) * size_t(f.ny + 1));
  for (int j = 0; j <= f.ny; ++j) {
    for (int i = 0; i <= f.nx; ++i) {
      const double x = f.x0 + i * f.cell, y = f.y0 + j * f.cell;
      double z = 0.0;
      for (const Vec3& w : waves) z += p.hill_amplitude * std::sin(w.x() * x + w.y() * y + w.z());
      f.z[size_t(j) * size_t(f.nx + 1) + size_t(i)] = z;
    }
  }
  f.UpdateTop();
  World world;
  const double hx = 0.5 * p.loop_x, hy = 0.5 * p.loop_y;
  world.path = Path({Vec3(-hx, -hy, 0), Vec3(hx, -hy, 0), Vec3(hx, hy, 0), Vec3(-hx, hy, 0)},
                    p.corner_radius, 0.5, [&f](double x, double y) { return f.Height(x, y); });
  Scene& s = world.scene;
  const double area_ha = 4 * p.extent * p.extent / 1e4;
  const int trees = int(std::lround(p.trees_per_hectare * area_ha));
  for (int k = 0; k < trees; ++k) {
    const double x = Uniform(rng, -p.extent + 5, p.extent - 5);
    const double y = Uniform(rng, -p.extent + 5, p.extent - 5);
    const double trunk = Uniform(rng, 2.5, 5.0), crown = Uniform(rng, 1.5, 3.0);
    const double radius = Uniform(rng, 0.15, 0.35);
    if (DistanceToPath(world.path, x, y) < p.clearance + crown) continue;
    const Vec3 base(x, y, f.Height(x, y) - 0.3);
    s.cylinders.push_back({base, radius, 0.3 + trunk + 0.5 * crown});
    s.spheres.push_back({base + Vec3(0, 0, 0.3 + trunk + 0.5 * crown), crown});
  }
  const int benches = int(std::lround(p.benches_per_hectare * area_ha));
  for (int k = 0; k < benches; ++k) {
    const double x = Uniform(rng, -p.extent + 5, p.extent - 5);
    const double y = Uniform(rng, -p.extent + 5, p.extent - 5);
    const Vec3 half = Uniform(rng, 0, 1) < 0.5 ? Vec3(0.9, 0.3, 0) : Vec3(0.3, 0.9, 0);
    if (DistanceToPath(world.path, x, y) < p.clearance + 1.0) continue;
    double ground = 1e300;
    for (const double sx : {-1.0, 1.0})
      for (const double sy : {-1.0, 1.0})
        ground = std::min(ground, f.Height(x + sx * half.x(), y + sy * half.y()));
    s.boxes.push_back(
        Box::Spanning(Vec3(x, y, ground - 0.1) - half, Vec3(x, y, ground + 0.8) + half));
  }
  s.fields.push_back(std::move(f));
  s.Build(8.0);
  world.start_range = world.path.Length();
  world.max_speed = 16.0;
  return world;
}

World BuildIndoorWorld(const IndoorParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kIndoor);
  const double D = p.depth, t = p.wall, st = p.storey, F = p.storey + p.slab;
  const double top = 2 * p.storey + p.slab, H = p.hall_length;
  // Partition positions of both storeys (the upper one scaled to the same total length).
  std::vector<double> xa{0.0}, xb{0.0};
  for (int k = 0; k < p.rooms; ++k)
    xa.push_back(xa.back() + Uniform(rng, p.room_length.lo, p.room_length.hi));
  for (int k = 0; k < p.rooms; ++k)
    xb.push_back(xb.back() + Uniform(rng, p.room_length.lo, p.room_length.hi));
  const double L = xa.back();
  for (double& x : xb) x *= L / xb.back();
  const double ya = 0.5 * D, yb = D + t + 0.5 * D;  // path lines of the storeys
  const double y0 = 0.5 * (ya + yb) - 0.5 * p.stair_run, y1 = y0 + p.stair_run;  // flights
  const double xw = -0.5 * H, xe = L + 0.5 * H;                                  // hall axes

  World world;
  Scene& s = world.scene;
  s.floors = {0.0};
  s.ceilings = {top};
  auto box = [&](const Vec3& a, const Vec3& b) { s.boxes.push_back(Box::Spanning(a, b)); };
  box(Vec3(-H - t, -t, 0), Vec3(L + H + t, 0, top));                     // south wall
  box(Vec3(-H - t, 2 * D + t, 0), Vec3(L + H + t, 2 * D + 2 * t, top));  // north wall
  box(Vec3(-H - t, -t, 0), Vec3(-H, 2 * D + 2 * t, top));                // west wall
  box(Vec3(L + H, -t, 0), Vec3(L + H + t, 2 * D + 2 * t, top));          // east wall
  box(Vec3(0, D, 0), Vec3(L, D + t, top));                               // between the strips
  box(Vec3(0, 0, st), Vec3(L, D, top));           // above the ground-floor rooms
  box(Vec3(0, D + t, 0), Vec3(L, 2 * D + t, F));  // below the upper-floor rooms
  // Partitions with a door on the path line, and tables away from it.
  auto storey = [&](const std::vector<double>& xs, double ylo, double yhi, double yd, double z0) {
    const double hw = 0.5 * p.door_width, z1 = z0 + p.storey;
    for (double x : xs) {
      box(Vec3(x - t / 2, ylo, z0), Vec3(x + t / 2, yd - hw, z1));
      box(Vec3(x - t / 2, yd + hw, z0), Vec3(x + t / 2, yhi, z1));
      box(Vec3(x - t / 2, yd - hw, z0 + p.door_height), Vec3(x + t / 2, yd + hw, z1));
    }
    for (size_t r = 0; r + 1 < xs.size(); ++r) {
      for (int k = 0; k < p.tables_per_room; ++k) {
        const double sx = Uniform(rng, 0.8, 1.6), sy = Uniform(rng, 0.6, 1.0);
        const double x = Uniform(rng, xs[r] + 0.5, xs[r + 1] - 0.5 - sx);
        const bool south = Uniform(rng, 0, 1) < 0.5;
        const double y =
            south ? Uniform(rng, ylo + 0.4, yd - 1.3 - sy) : Uniform(rng, yd + 1.3, yhi - 0.4 - sy);
        box(Vec3(x, y, z0), Vec3(x + sx, y + sy, z0 + 0.75));
      }
    }
  };
  storey(xa, 0.0, D, ya, 0.0);
  storey(xb, D + t, 2 * D + t, yb, F);
  // Stair halls: a straight flight rising northwards on the hall axis, a landing at the top.
  const double tread = p.stair_run / p.steps, rise = F / p.steps;
  for (const double xc : {xw, xe}) {
    for (int k = 0; k < p.steps; ++k) {
      // Step k: its tread and the solid below it (the flight is their union).
      box(Vec3(xc - 0.5 * p.stair_width, y0 + k * tread, 0),
          Vec3(xc + 0.5 * p.stair_width, y0 + (k + 1) * tread, (k + 1) * rise));
    }
    box(Vec3(xc - 0.5 * H, y1, st), Vec3(xc + 0.5 * H, 2 * D + t, F));
  }
  s.Build(1.0);
  world.path = Path({Vec3(xw, ya, 0), Vec3(xe, ya, 0), Vec3(xe, y0, 0), Vec3(xe, y1, F),
                     Vec3(xe, yb, F), Vec3(xw, yb, F), Vec3(xw, y1, F), Vec3(xw, y0, 0)},
                    1.2, 0.5);
  world.start_range = world.path.Length();
  world.max_speed = 2.0;
  return world;
}

}  // namespace ctlio::sim
