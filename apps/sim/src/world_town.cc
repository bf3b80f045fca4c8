// The town street (KITTI-like; parameters in worlds.h, TownParams).
#include <algorithm>
#include <cmath>

#include "ctlio/sim/random_draw.h"
#include "ctlio/sim/worlds.h"
#include "world_content.h"

namespace ctlio::sim {

World BuildTownWorld(const TownParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kTown);
  auto U = [&](double lo, double hi) { return Uniform(rng, lo, hi); };
  auto R = [&](const Range& r) { return Uniform(rng, r.lo, r.hi); };
  World w;
  Scene& s = w.scene;
  s.seed = seed;
  s.floors = {0.0};
  const VegetationParams& veg = p.vegetation;
  s.relief = veg.relief;
  const double rh = p.road_half_width, pav = p.pavement;
  const std::vector<Vec3> road = {Vec3(0, 0, 0), Vec3(p.length, 0, 0), Vec3(p.length, p.width, 0),
                                  Vec3(0, p.width, 0)};
  for (int side = 0; side < 4; ++side) {
    const Vec3 A = road[side], B = road[(side + 1) % 4];
    const double len = (B - A).norm();
    const Vec3 u = (B - A) / len;
    const Vec3 out(u.y(), -u.x(), 0.0);  // right of the travel direction: outside the block
    const double a_lo = p.corner_clear, a_hi = len - p.corner_clear;
    for (const double sign : {1.0, -1.0}) {
      const Vec3 n = sign * out;
      auto at = [&](double along, double lateral, double z) -> Vec3 {
        return A + along * u + lateral * n + Vec3(0, 0, z);
      };
      // The façade that faces the street, and the two ends (seen through the gaps).
      const Vec3 f = -n;
      const int facing = f.y() < -0.5 ? 1 : f.x() > 0.5 ? 2 : f.y() > 0.5 ? 4 : 8;
      const int ends = (facing == 1 || facing == 4) ? (2 | 8) : (1 | 4);
      // Raised pavement (kerb 0.12 m).
      s.boxes.push_back(Box::Spanning(at(a_lo - 4, rh, -0.1), at(a_hi + 4, rh + pav, 0.12)));
      // Houses behind front gardens: hedges, grass, bushes, a garden tree.
      for (double a = a_lo; a < a_hi - 6.0;) {
        const double width = std::min(R(p.house_width), a_hi - a);
        const double garden = R(p.garden), depth = R(p.house_depth);
        const double f0 = rh + pav + garden;
        const int storeys = p.min_storeys + int(U(0, p.max_storeys - p.min_storeys + 1));
        content::FacadeStyle st;
        st.window_width = U(0.9, 1.6);
        st.pier = U(0.8, 2.0);
        st.recess = U(0.15, 0.3);
        st.glass_fraction = U(0.5, 0.9);
        st.balcony_probability = U(0, 0.25);
        st.ledge_probability = U(0, 0.6);
        st.cornice = U(0, 1) < 0.5;
        content::AddBuilding(s, rng, at(a, f0, 0).cwiseMin(at(a + width, f0 + depth, 0)),
                             at(a, f0, 0).cwiseMax(at(a + width, f0 + depth, 0)), storeys,
                             U(2.8, 3.3), facing | (U(0, 1) < 0.5 ? ends : 0), st);
        if (garden > 1.5) {
          const Vec3 g0 = at(a, rh + pav, 0), g1 = at(a + width, f0, 0);
          const Vec3 lo = g0.cwiseMin(g1), hi = g0.cwiseMax(g1);
          s.covers.push_back({lo.x(), lo.y(), hi.x(), hi.y(), veg.grass_height, veg.grass_free_path,
                              veg.grass_relief});
          if (U(0, 1) < p.hedge_probability) {
            content::AddHedge(s, at(a + 0.3, rh + pav + 0.1, 0),
                              at(a + width - 0.3, rh + pav + U(0.6, 1.2), 0), U(1.1, 2.2),
                              veg.hedge_free_path);
          }
          for (int k = 1 + int(U(0, 4)); k > 0; --k) {
            content::AddBush(s, rng, at(a + U(1, width - 1), rh + pav + 0.5 * garden + 0.4, 0),
                             std::min(U(0.6, 1.6), 0.45 * garden), veg.bush_free_path);
          }
          if (garden > 3.0 && U(0, 1) < 0.8) {
            content::AddTree(s, rng, at(a + U(2, width - 2), rh + pav + 0.5 * garden, 0),
                             U(0.5, 0.9), veg.crown_free_path);
          }
        }
        const double gap = R(p.gap);
        if (gap > 3.0) {  // a side garden: a tree or a large bush between the houses
          const Vec3 base = at(a + width + 0.5 * gap, f0 + U(1, depth), 0);
          if (U(0, 1) < 0.5) {
            content::AddTree(s, rng, base, U(0.4, 0.8), veg.crown_free_path);
          } else {
            content::AddBush(s, rng, base, 0.45 * gap, veg.bush_free_path);
          }
        }
        a += width + gap;
      }
      // Street trees at the kerb, parked cars, poles, people.
      for (double a = a_lo + 0.5 * R(p.street_tree_spacing); a < a_hi;
           a += R(p.street_tree_spacing)) {
        content::AddTree(s, rng, at(a, rh + 0.8, 0.12), U(0.8, 1.3), veg.crown_free_path);
      }
      for (double a = a_lo; a + 6.0 < a_hi; a += 6.0) {
        if (U(0, 1) >= p.car_probability) continue;
        const Vec3 c = at(a + 3.0, rh - 1.05, 0);
        content::AddCar(s, rng, c, std::abs(u.x()) > 0.5);
      }
      for (double a = a_lo + 0.5 * R(p.pole_spacing); a < a_hi; a += R(p.pole_spacing)) {
        content::AddPole(s, rng, at(a, rh + 0.35, 0.12));
      }
      const int people = int(std::lround(p.people_per_100m * (a_hi - a_lo) / 100.0));
      for (int k = 0; k < people; ++k) {
        content::AddPerson(s, rng, at(U(a_lo, a_hi), rh + U(1.2, pav - 0.4), 0.12));
      }
    }
  }
  // People walking along the pavements (drawn last: the static world is the same without them).
  for (int side = 0; side < 4; ++side) {
    const Vec3 A = road[side], B = road[(side + 1) % 4];
    const double len = (B - A).norm();
    const Vec3 u = (B - A) / len, out(u.y(), -u.x(), 0.0);
    for (const double sign : {1.0, -1.0}) {
      const int n = int(std::lround(p.walkers_per_100m * (len - 2 * p.corner_clear) / 100.0));
      for (int k = 0; k < n; ++k) {
        const double a0 = U(p.corner_clear, len - p.corner_clear - 25.0), lane = U(1.0, pav - 0.8);
        const Vec3 a = A + a0 * u + sign * (rh + lane) * out + Vec3(0, 0, 0.12);
        s.movers.push_back({a, a + U(10, 25) * u, U(0.9, 1.6), U(0, 100), 0.22, U(1.6, 1.85)});
      }
    }
  }
  s.Build(4.0);
  const double o = p.lane_offset;
  w.path = Path({Vec3(-o, -o, 0), Vec3(p.length + o, -o, 0), Vec3(p.length + o, p.width + o, 0),
                 Vec3(-o, p.width + o, 0)},
                p.corner_radius, 0.5);
  w.start_range = w.path.Length();
  w.max_speed = 20.0;
  return w;
}

}  // namespace ctlio::sim
