// The college quad (Newer College-like; parameters in worlds.h, QuadParams).
#include <algorithm>
#include <cmath>

#include "ctlio/sim/random_draw.h"
#include "ctlio/sim/worlds.h"
#include "quad_park.h"
#include "world_content.h"

namespace ctlio::sim {

World BuildQuadWorld(const QuadParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kQuad);
  auto U = [&](double lo, double hi) { return Uniform(rng, lo, hi); };
  World world;
  Scene& s = world.scene;
  s.seed = seed;
  s.floors = {0.0};
  VegetationParams veg = p.vegetation;
  s.relief = veg.relief;
  const double Lx = p.lawn_x, Ly = p.lawn_y, w = p.walkway;
  const double yc = 0.5 * Ly;  // the arch's axis
  const double D = U(p.depth.lo, p.depth.hi);
  const double park_x0 = Lx + w + D + p.park_gap, park_x1 = park_x0 + p.park;
  const double park_y0 = yc - 0.5 * p.park, park_y1 = yc + 0.5 * p.park;
  s.covers.push_back({0.0, 0.0, Lx, Ly, veg.grass_height, veg.grass_free_path, veg.grass_relief});
  s.covers.push_back({park_x0, park_y0, park_x1, park_y1, veg.grass_height, veg.grass_free_path,
                      veg.grass_relief});

  // The path: round the quad 2 m from the façades, through the arch, round the park and back.
  const double xe = Lx + w - 2.0, x1 = park_x0 + 10.0, x2 = park_x1 - 10.0;
  const double ys = park_y0 + 10.0, yn = park_y1 - 10.0, lane = 1.2;
  world.path = Path(
      {Vec3(2 - w, 2 - w, 0), Vec3(xe, 2 - w, 0), Vec3(xe, yc - lane, 0), Vec3(x1, yc - lane, 0),
       Vec3(x1, ys, 0), Vec3(x2, ys, 0), Vec3(x2, yn, 0), Vec3(x1, yn, 0), Vec3(x1, yc + lane, 0),
       Vec3(xe, yc + lane, 0), Vec3(xe, Ly + w - 2, 0), Vec3(2 - w, Ly + w - 2, 0)},
      1.0, 0.5);

  // The four ranges, each a row of buildings of random length, height and windows; only the
  // façades that can be seen get windows (the quad side; the east range's park side).
  // A range along x from xa to xb (y ∈ [y0, y1]) or along y (x ∈ [y0, y1]), split into buildings.
  auto range = [&](bool along_x, double a0, double a1, double b0, double b1, int facades) {
    for (double a = a0; a < a1 - 1.0;) {
      double len = std::min(U(p.segment.lo, p.segment.hi), a1 - a);
      if (a1 - (a + len) < 6.0) len = a1 - a;
      const int storeys = 3 + int(U(0, 2));
      const Vec3 lo = along_x ? Vec3(a, b0, 0) : Vec3(b0, a, 0);
      const Vec3 hi = along_x ? Vec3(a + len, b1, 0) : Vec3(b1, a + len, 0);
      content::AddBuilding(s, rng, lo, hi, storeys, p.storey * U(0.95, 1.05), facades,
                           content::CollegeFacadeStyle(rng));
      a += len;
    }
  };
  range(true, -w - D, Lx + w + D, -w - D, -w, 1 << 2);          // south range, façade north
  range(true, -w - D, Lx + w + D, Ly + w, Ly + w + D, 1 << 0);  // north range, façade south
  range(false, -w, Ly + w, -w - D, -w, 1 << 1);                 // west range, façade east
  // East range: two parts either side of the arch and the range above the passage.
  const double a0 = yc - 0.5 * p.arch_width, a1 = yc + 0.5 * p.arch_width;
  range(false, -w, a0, Lx + w, Lx + w + D, (1 << 3) | (1 << 1));
  range(false, a1, Ly + w, Lx + w, Lx + w + D, (1 << 3) | (1 << 1));
  s.boxes.push_back(
      Box::Spanning(Vec3(Lx + w, a0, p.arch_height), Vec3(Lx + w + D, a1, 3 * p.storey)));

  auto clear_of_path = [&](double x, double y, double r) {
    return content::DistanceToPath(world.path, x, y) > r;
  };
  // Quad: trees at the lawn's corners, people and benches on the walkway.
  for (int k = 0; k < p.quad_trees; ++k) {
    const double x = k % 2 == 0 ? U(4, 9) : Lx - U(4, 9), y = k / 2 == 0 ? U(4, 8) : Ly - U(4, 8);
    const double size = U(0.6, 1.0);
    // A crown reaches at most 1.35 × 3.6 m × size from its trunk (AddTree).
    if (!clear_of_path(x, y, 4.9 * size + 0.5)) continue;
    content::AddTree(s, rng, Vec3(x, y, 0), size, veg.crown_free_path);
  }
  for (int k = 0; k < p.people; ++k) {
    const double x = U(0, Lx), y = U(0, 1) < 0.5 ? U(1, 6) : Ly - U(1, 6);
    if (clear_of_path(x, y, 1.2)) content::AddPerson(s, rng, Vec3(x, y, 0));
  }
  // Park: hedges along its west side and round a bed, trees, bushes, benches.
  s.media.push_back({Vec3(park_x0 + 1.0, yc - 0.5 * p.park + 15, 0.7),
                     Vec3(0.6, 0.5 * p.park - 25.0, 0.7), veg.hedge_free_path, true});
  const double area_ha = p.park * p.park / 1e4;
  for (int k = 0, n = int(std::lround(p.park_trees_per_hectare * area_ha)); k < n; ++k) {
    const double x = U(park_x0 + 3, park_x1 - 3), y = U(park_y0 + 3, park_y1 - 3);
    if (!clear_of_path(x, y, 8.5)) continue;
    content::AddTree(s, rng, Vec3(x, y, 0), U(0.6, 1.2), veg.crown_free_path);
  }
  for (int k = 0, n = int(std::lround(p.park_bushes_per_hectare * area_ha)); k < n; ++k) {
    const double x = U(park_x0 + 2, park_x1 - 2), y = U(park_y0 + 2, park_y1 - 2);
    const double size = U(0.5, 1.5);
    if (!clear_of_path(x, y, 2.5 + 1.3 * size)) continue;
    content::AddBush(s, rng, Vec3(x, y, 0), size, veg.bush_free_path);
  }
  for (int k = 0; k < p.benches; ++k) {
    const double x = U(x1 + 2.5, x2 - 2.5), y = U(0, 1) < 0.5 ? ys + 2.2 : yn - 2.2;
    content::AddBench(s, Vec3(x, y, 0), true);
  }
  // Walking people (drawn last: the static world is the same with or without them): on the
  // lawn, and in the park on lanes clear of the path.
  auto clear_lane = [&](const Vec3& a, const Vec3& b) {
    for (int k = 0; k <= 10; ++k) {
      const Vec3 q = a + 0.1 * k * (b - a);
      if (!clear_of_path(q.x(), q.y(), 2.5)) return false;
    }
    return true;
  };
  for (int k = 0; k < p.walkers; ++k) {
    const bool lawn = k < p.walkers / 2;
    const double x0 = lawn ? 4 : park_x0 + 5, x1 = lawn ? Lx - 4 : park_x1 - 5;
    const double y0 = lawn ? 4 : park_y0 + 5, y1 = lawn ? Ly - 4 : park_y1 - 5;
    const Vec3 a(U(x0, x1), U(y0, y1), 0), b(U(x0, x1), U(y0, y1), 0);
    const double speed = U(0.9, 1.6), phase = U(0, 100);
    if (clear_lane(a, b)) s.movers.push_back({a, b, speed, phase, 0.22, U(1.6, 1.85)});
  }
  // The park's rim, path furniture and mound, from their own generator (quad_park.h).
  FurnishPark(s, world.path, {park_x0, park_y0, park_x1, park_y1}, seed);
  s.Build(4.0);
  world.start_range = world.path.Length();
  world.max_speed = 2.5;
  return world;
}

}  // namespace ctlio::sim
