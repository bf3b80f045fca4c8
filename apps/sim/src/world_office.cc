// The office floor (parameters in worlds.h, OfficeParams).
#include <algorithm>
#include <cmath>

#include "ctlio/sim/random_draw.h"
#include "ctlio/sim/worlds.h"
#include "world_content.h"

namespace ctlio::sim {

World BuildOfficeWorld(const OfficeParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kOffice);
  auto U = [&](double lo, double hi) { return Uniform(rng, lo, hi); };
  World world;
  Scene& s = world.scene;
  s.seed = seed;
  s.floors = {0.0};
  s.ceilings = {p.height};
  const double X = p.size_x, Y = p.size_y, H = p.height, t = 0.3;
  auto box = [&](const Vec3& a, const Vec3& b) { s.boxes.push_back(Box::Spanning(a, b)); };
  // End walls plain; the long walls get windows facing inwards (openings show the outer wall's
  // back, or glass).
  box(Vec3(-t, -t - 0.2, 0), Vec3(0, Y + t + 0.2, H));
  box(Vec3(X, -t - 0.2, 0), Vec3(X + t, Y + t + 0.2, H));
  content::FacadeStyle st;
  st.recess = 0.2;
  st.window_width = 1.6;
  st.window_height = 1.5;
  st.pier = 1.0;
  st.sill = 0.8;
  st.glass_fraction = 0.7;
  st.balcony_probability = st.ledge_probability = st.door_probability = 0.0;
  st.cornice = false;
  box(Vec3(0, -t - 0.2, 0), Vec3(X, -0.2, H));
  box(Vec3(0, Y + 0.2, 0), Vec3(X, Y + t + 0.2, H));
  content::AddFacade(s, rng, {Vec3(0, -0.2, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, X, 1, H, st);
  content::AddFacade(s, rng, {Vec3(0, Y + 0.2, 0), Vec3(1, 0, 0), Vec3(0, -1, 0)}, X, 1, H, st);
  // The core (meeting rooms) and the path loop round it in the middle of the aisle.
  const Vec3 c(0.5 * X, 0.5 * Y, 0);
  const double cx = 0.5 * p.core_x, cy = 0.5 * p.core_y, a = p.aisle;
  box(c - Vec3(cx, cy, 0), c + Vec3(cx, cy, H));
  const double px = cx + 0.5 * a, py = cy + 0.5 * a;
  world.path =
      Path({c + Vec3(-px, -py, 0), c + Vec3(px, -py, 0), c + Vec3(px, py, 0), c + Vec3(-px, py, 0)},
           0.8, 0.5);
  // Shelves along the core's long sides, with gaps for doors.
  for (const double sy : {-1.0, 1.0}) {
    for (double x = -cx + 0.5; x < cx - 2.0;) {
      const double len = std::min(U(1.6, 3.2), cx - 0.5 - x);
      if (U(0, 1) < 0.7) {
        content::AddShelf(s, rng, c + Vec3(x, sy * cy, 0), len, true, sy > 0);
      }
      x += len + U(0.3, 1.8);
    }
  }
  // Outside the aisle: desk rows towards the windows (x along), chairs, screens; columns.
  const double free_x = cx + a, free_y = cy + a;  // the aisle's outer edge from the centre
  for (const double sy : {-1.0, 1.0}) {
    const double y0 = sy > 0 ? c.y() + free_y + 0.6 : 1.2,
                 y1 = sy > 0 ? Y - 1.2 : c.y() - free_y - 0.6;
    for (double y = y0; y + 1.7 < y1; y += U(3.0, 3.6)) {
      for (double x = 2.0; x + 1.8 < X - 2.0; x += U(1.7, 2.1)) {
        if (U(0, 1) < 0.15) continue;
        content::AddDesk(s, rng, Vec3(x, y, 0), true);
        content::AddChair(s, rng,
                          Vec3(x + U(0.5, 1.1), y + U(-0.45, -0.3) + (U(0, 1) < 0.5 ? 0 : 1.6), 0));
      }
      if (U(0, 1) < 0.6) box(Vec3(2.0, y + 0.85, 0), Vec3(X - 2.0, y + 0.9, 1.25));  // screen
    }
  }
  // The aisle's ends: shelves and cabinets on the end walls, plants in the corners.
  for (const double x0 : {0.0, X}) {
    const bool west = x0 == 0.0;
    for (double y = 1.0; y < Y - 2.0;) {
      const double len = U(1.0, 2.8);
      if (U(0, 1) < 0.5) {
        content::AddShelf(s, rng, Vec3(x0, y, 0), std::min(len, Y - 1.0 - y), false, west);
      } else {
        const double d = U(0.4, 0.6), h = U(0.8, 1.4);
        box(Vec3(x0 + (west ? 0 : -d), y, 0), Vec3(x0 + (west ? d : 0), y + len, h));
      }
      y += len + U(0.2, 1.0);
    }
  }
  // Meeting tables with chairs between the aisle's ends and the end walls.
  for (const double sx : {-1.0, 1.0}) {
    const double x_in = c.x() + sx * (px + 1.3), x_out = sx < 0 ? 1.6 : X - 1.6;
    for (const double y : {c.y() - 2.5, c.y() + 1.0}) {
      const double xa = std::min(x_in, x_out), xb = std::max(x_in, x_out);
      if (xb - xa < 3.0) continue;
      const double x = U(xa, xb - 2.4);
      box(Vec3(x, y, 0.72), Vec3(x + 2.4, y + 1.2, 0.76));
      box(Vec3(x + 1.1, y + 0.5, 0), Vec3(x + 1.3, y + 0.7, 0.72));
      for (const double cxk : {x + 0.5, x + 1.9}) {
        content::AddChair(s, rng, Vec3(cxk, y - 0.35, 0));
        content::AddChair(s, rng, Vec3(cxk, y + 1.55, 0));
      }
    }
  }
  for (int k = 0; k < p.plants; ++k) {
    const double x = U(1.0, X - 1.0), y = U(0, 1) < 0.5 ? U(0.8, 1.1) : Y - U(0.8, 1.1);
    content::AddPlant(s, rng, Vec3(x, y, 0));
  }
  for (double x = 4.0; x < X - 2.0; x += 8.0) {  // columns on the aisle's outer edge
    for (const double y : {c.y() - free_y - 0.2, c.y() + free_y + 0.2}) {
      s.boxes.push_back(Box::Spanning(Vec3(x - 0.25, y - 0.25, 0), Vec3(x + 0.25, y + 0.25, H)));
    }
  }
  for (double x = 3.0; x < X - 1.0; x += 4.0) {  // ceiling lamps
    for (double y = 3.0; y < Y - 1.0; y += 4.5) {
      s.boxes.push_back(
          Box::Spanning(Vec3(x - 0.6, y - 0.15, H - 0.12), Vec3(x + 0.6, y + 0.15, H)));
    }
  }
  s.Build(1.0);
  world.start_range = world.path.Length();
  world.max_speed = 2.0;
  return world;
}

}  // namespace ctlio::sim
