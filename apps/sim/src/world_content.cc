#include "world_content.h"

#include <algorithm>
#include <cmath>

#include "ctlio/sim/random_draw.h"

namespace ctlio::sim::content {
namespace {

void AddBox(Scene& s, const Vec3& a, const Vec3& b) { s.boxes.push_back(Box::Spanning(a, b)); }

}  // namespace

double DistanceToPath(const Path& path, double x, double y) {
  double d2 = 1e300;
  for (const Vec3& q : path.ControlPoints()) {
    d2 = std::min(d2, (q.x() - x) * (q.x() - x) + (q.y() - y) * (q.y() - y));
  }
  return std::sqrt(d2);
}

double AddTree(Scene& s, std::mt19937_64& rng, const Vec3& base, double size, double free_path) {
  const double radius = size * Uniform(rng, 2.2, 3.6);
  const double vertical = radius * Uniform(rng, 0.8, 1.2);
  const double bottom = Uniform(rng, 1.8, 3.5);
  const int lobes = 1 + int(Uniform(rng, 0, 3));
  const Vec3 centre = base + Vec3(0, 0, bottom + vertical);
  s.cylinders.push_back(
      {base - Vec3(0, 0, 0.2), Uniform(rng, 0.12, 0.3) * std::sqrt(size), bottom + vertical + 0.2});
  s.media.push_back({centre, Vec3(radius, radius, vertical), free_path, false});
  double reach = radius;
  for (int k = 1; k < lobes; ++k) {
    const double heading = Uniform(rng, 0, 2 * M_PI), r = radius * Uniform(rng, 0.5, 0.8);
    const Vec3 offset(0.55 * radius * std::cos(heading), 0.55 * radius * std::sin(heading),
                      Uniform(rng, -0.3, 0.4) * vertical);
    s.media.push_back({centre + offset, Vec3(r, r, r * Uniform(rng, 0.8, 1.1)), free_path, false});
    reach = std::max(reach, 0.55 * radius + r);
  }
  return reach;
}

void AddBush(Scene& s, std::mt19937_64& rng, const Vec3& base, double size, double free_path) {
  const double rx = size * Uniform(rng, 0.7, 1.3), ry = size * Uniform(rng, 0.7, 1.3);
  const double rz = size * Uniform(rng, 0.5, 0.9);
  s.media.push_back({base + Vec3(0, 0, 0.7 * rz), Vec3(rx, ry, rz), free_path, false});
}

void AddHedge(Scene& s, const Vec3& a, const Vec3& b, double height, double free_path) {
  const Vec3 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  const Vec3 centre(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z() + 0.5 * height);
  s.media.push_back({centre, Vec3(0.5 * (hi.x() - lo.x()), 0.5 * (hi.y() - lo.y()), 0.5 * height),
                     free_path, true});
}

FacadeStyle CollegeFacadeStyle(std::mt19937_64& rng) {
  FacadeStyle st;
  st.window_width = Uniform(rng, 0.9, 1.5);
  st.window_height = Uniform(rng, 1.4, 2.0);
  st.pier = Uniform(rng, 0.9, 2.2);
  st.recess = Uniform(rng, 0.2, 0.35);
  st.glass_fraction = Uniform(rng, 0.2, 0.6);
  return st;
}

void AddFacade(Scene& s, std::mt19937_64& rng, const Facade& F, double L, int storeys,
               double storey, const FacadeStyle& st) {
  const double r = st.recess, top = storeys * storey;
  const int n = std::max(0, int(std::floor((L - st.pier) / (st.window_width + st.pier))));
  const double gap = (L - n * st.window_width) / (n + 1);
  for (int k = 0; k < storeys; ++k) {
    const double z0 = k * storey, z1 = z0 + storey;
    double u = 0.0;
    for (int i = 0; i < n; ++i) {
      const double u0 = gap + i * (st.window_width + gap), u1 = u0 + st.window_width;
      const bool door = k == 0 && Uniform(rng, 0, 1) < st.door_probability;
      const bool balcony = k > 0 && Uniform(rng, 0, 1) < st.balcony_probability;
      const bool glass = Uniform(rng, 0, 1) < st.glass_fraction;
      const double zb = door || balcony ? z0 : z0 + st.sill;
      const double zt = door ? z0 + std::min(2.3, storey - 0.3) : zb + st.window_height;
      AddBox(s, F.At(u, 0, z0), F.At(u0, r, z1));  // pier
      if (zb > z0) AddBox(s, F.At(u0, 0, z0), F.At(u1, r, zb));
      AddBox(s, F.At(u0, 0, std::min(zt, z1)), F.At(u1, r, z1));
      if (!door && !balcony) {  // a mullion in the middle of the opening
        const double um = 0.5 * (u0 + u1);
        AddBox(s, F.At(um - 0.05, 0.3 * r, zb), F.At(um + 0.05, r, zt));
      }
      if (glass && !door) {
        s.glass.push_back(Box::Spanning(F.At(u0, 0.4 * r, zb), F.At(u1, 0.5 * r, zt)));
      }
      if (balcony) {
        AddBox(s, F.At(u0 - 0.4, r, z0 - 0.18), F.At(u1 + 0.4, r + 1.1, z0));
        AddBox(s, F.At(u0 - 0.4, r + 1.05, z0), F.At(u1 + 0.4, r + 1.1, z0 + 1.0));
        for (const double ue : {u0 - 0.4, u1 + 0.35}) {
          AddBox(s, F.At(ue, r, z0), F.At(ue + 0.05, r + 1.1, z0 + 1.0));
        }
      }
      u = u1;
    }
    AddBox(s, F.At(u, 0, z0), F.At(L, r, z1));  // last pier
    if (k > 0 && Uniform(rng, 0, 1) < st.ledge_probability) {
      AddBox(s, F.At(0, r, z0 - 0.12), F.At(L, r + 0.15, z0 + 0.08));
    }
  }
  if (st.cornice) AddBox(s, F.At(0, r, top - 0.35), F.At(L, r + 0.3, top));
}

void AddBuilding(Scene& s, std::mt19937_64& rng, const Vec3& lo, const Vec3& hi, int storeys,
                 double storey, int facades, const FacadeStyle& st) {
  const double r = st.recess, top = lo.z() + storeys * storey;
  AddBox(s, Vec3(lo.x() + r, lo.y() + r, lo.z()), Vec3(hi.x() - r, hi.y() - r, top));
  const double lx = hi.x() - lo.x(), ly = hi.y() - lo.y();
  // South, east, north, west: start corner, direction along, outward normal; length.
  const Facade sides[4] = {{Vec3(lo.x(), lo.y() + r, lo.z()), Vec3(1, 0, 0), Vec3(0, -1, 0)},
                           {Vec3(hi.x() - r, lo.y(), lo.z()), Vec3(0, 1, 0), Vec3(1, 0, 0)},
                           {Vec3(lo.x(), hi.y() - r, lo.z()), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                           {Vec3(lo.x() + r, lo.y(), lo.z()), Vec3(0, 1, 0), Vec3(-1, 0, 0)}};
  const double lengths[4] = {lx, ly, lx, ly};
  for (int f = 0; f < 4; ++f) {
    if (facades & (1 << f)) {
      AddFacade(s, rng, sides[f], lengths[f], storeys, storey, st);
    } else {  // a plain wall
      AddBox(s, sides[f].At(0, 0, 0), sides[f].At(lengths[f], r, top - lo.z()));
    }
  }
}

void AddCar(Scene& s, std::mt19937_64& rng, const Vec3& c, bool along_x) {
  const double half_len = 0.5 * Uniform(rng, 4.0, 4.8), half_w = 0.5 * Uniform(rng, 1.72, 1.9);
  const double roof = Uniform(rng, 1.38, 1.6);
  // Boxes in car coordinates (a along the car, b across), mapped to the world.
  auto box = [&](double a0, double b0, double z0, double a1, double b1, double z1) {
    const Vec3 p = along_x ? Vec3(a0, b0, z0) : Vec3(b0, a0, z0);
    const Vec3 q = along_x ? Vec3(a1, b1, z1) : Vec3(b1, a1, z1);
    return Box::Spanning(c + p, c + q);
  };
  const double L = half_len, W = half_w;
  for (const double a : {-L + 0.75, L - 0.85}) {  // wheels
    for (const double b : {-W + 0.02, W - 0.27})
      s.boxes.push_back(box(a - 0.32, b, 0.0, a + 0.32, b + 0.25, 0.64));
  }
  s.boxes.push_back(box(-L, -W, 0.3, L, W, 0.55));                             // bumpers to sills
  s.boxes.push_back(box(-L + 0.1, -W + 0.02, 0.55, L - 0.1, W - 0.02, 0.8));   // body
  s.boxes.push_back(box(-L + 0.3, -W + 0.06, 0.8, L - 0.35, W - 0.06, 0.92));  // shoulders
  const double c0 = -L + 0.9, c1 = L - 1.5;                                    // cabin
  s.glass.push_back(box(c0, -W + 0.12, 0.92, c1, W - 0.12, roof - 0.08));
  s.boxes.push_back(box(c0 + 0.2, -W + 0.2, roof - 0.08, c1 - 0.1, W - 0.2, roof));
  s.boxes.push_back(box(c0 + 0.3, -W + 0.3, 0.92, c1 - 0.3, W - 0.3, roof - 0.3));  // seats
}

void AddPole(Scene& s, std::mt19937_64& rng, const Vec3& base) {
  const double height = Uniform(rng, 3.0, 8.0), radius = Uniform(rng, 0.05, 0.13);
  s.cylinders.push_back({base, radius, height});
  if (Uniform(rng, 0, 1) < 0.5) {  // lamp head
    s.boxes.push_back(
        Box::Spanning(base + Vec3(-0.35, -0.12, height - 0.2), base + Vec3(0.35, 0.12, height)));
  } else {  // sign plate
    const double z = Uniform(rng, 2.0, std::min(3.0, height - 0.6));
    s.boxes.push_back(
        Box::Spanning(base + Vec3(-0.32, radius, z), base + Vec3(0.32, radius + 0.04, z + 0.6)));
  }
}

void AddPerson(Scene& s, std::mt19937_64& rng, const Vec3& base) {
  const double k = Uniform(rng, 0.9, 1.1);
  s.cylinders.push_back({base, 0.17 * k, 0.85 * k});
  s.cylinders.push_back({base + Vec3(0, 0, 0.85 * k), 0.22 * k, 0.6 * k});
  s.spheres.push_back({base + Vec3(0, 0, 1.58 * k), 0.11 * k});
}

void AddBench(Scene& s, const Vec3& c, bool along_x) {
  const Vec3 ax = along_x ? Vec3(1, 0, 0) : Vec3(0, 1, 0),
             ay = along_x ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
  auto box = [&](double a0, double b0, double z0, double a1, double b1, double z1) {
    s.boxes.push_back(Box::Spanning(c + a0 * ax + b0 * ay + Vec3(0, 0, z0),
                                    c + a1 * ax + b1 * ay + Vec3(0, 0, z1)));
  };
  box(-0.9, -0.22, 0.42, 0.9, 0.22, 0.48);
  box(-0.9, 0.22, 0.5, 0.9, 0.28, 0.95);
  for (const double a : {-0.8, 0.74}) box(a, -0.22, 0.0, a + 0.06, 0.28, 0.42);
}

void AddDesk(Scene& s, std::mt19937_64& rng, const Vec3& b, bool along_x) {
  const double w = Uniform(rng, 1.4, 1.8), d = Uniform(rng, 0.7, 0.9), h = Uniform(rng, 0.72, 0.76);
  const Vec3 ex = along_x ? Vec3(w, 0, 0) : Vec3(0, w, 0),
             ey = along_x ? Vec3(0, d, 0) : Vec3(d, 0, 0);
  const Vec3 tx = ex.normalized() * 0.03;
  AddBox(s, b + Vec3(0, 0, h - 0.03), b + ex + ey + Vec3(0, 0, h));
  AddBox(s, b, b + tx + ey + Vec3(0, 0, h - 0.03));
  AddBox(s, b + ex - tx, b + ex + ey + Vec3(0, 0, h - 0.03));
  // A monitor and a box of clutter on top.
  const Vec3 m = b + 0.5 * ex + 0.75 * ey + Vec3(0, 0, h);
  AddBox(s, m - 0.28 * ex.normalized(),
         m + 0.28 * ex.normalized() + 0.04 * ey.normalized() + Vec3(0, 0, 0.45));
  const Vec3 q = b + Uniform(rng, 0.1, 0.6) * ex + Uniform(rng, 0.1, 0.4) * ey + Vec3(0, 0, h);
  AddBox(s, q,
         q + Vec3(Uniform(rng, 0.15, 0.4), Uniform(rng, 0.15, 0.35), Uniform(rng, 0.03, 0.25)));
}

void AddChair(Scene& s, std::mt19937_64& rng, const Vec3& b) {
  const double turn = Uniform(rng, 0, 1);
  const Vec3 back = turn < 0.25   ? Vec3(0.22, 0, 0)
                    : turn < 0.5  ? Vec3(-0.22, 0, 0)
                    : turn < 0.75 ? Vec3(0, 0.22, 0)
                                  : Vec3(0, -0.22, 0);
  s.cylinders.push_back({b, 0.3, 0.08});  // base
  s.cylinders.push_back({b, 0.03, 0.45});
  AddBox(s, b + Vec3(-0.25, -0.25, 0.44), b + Vec3(0.25, 0.25, 0.5));
  const Vec3 t = Vec3(std::abs(back.y()), std::abs(back.x()), 0) / 0.22 * 0.24;
  AddBox(s, b + back - t + Vec3(0, 0, 0.55), b + 1.15 * back + t + Vec3(0, 0, 1.0));
}

void AddShelf(Scene& s, std::mt19937_64& rng, const Vec3& b, double length, bool along_x,
              bool facing_positive) {
  const double depth = 0.35, height = Uniform(rng, 1.8, 2.2);
  const Vec3 ex = along_x ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  const Vec3 ey = (along_x ? Vec3(0, 1, 0) : Vec3(1, 0, 0)) * (facing_positive ? 1.0 : -1.0);
  auto box = [&](double a0, double b0, double z0, double a1, double b1, double z1) {
    AddBox(s, b + a0 * ex + b0 * ey + Vec3(0, 0, z0), b + a1 * ex + b1 * ey + Vec3(0, 0, z1));
  };
  box(0, 0, 0, length, 0.02, height);  // back panel
  box(0, 0, 0, 0.02, depth, height);
  box(length - 0.02, 0, 0, length, depth, height);
  const int boards = 4 + int(Uniform(rng, 0, 2));
  for (int k = 0; k <= boards; ++k) {
    const double z = 0.08 + k * (height - 0.1) / boards;
    box(0, 0, z - 0.02, length, depth, z);
    if (k == boards) break;
    // Runs of books or boxes: random widths, heights and depths, with gaps.
    for (double a = 0.03; a < length - 0.05;) {
      const double w = std::min(Uniform(rng, 0.08, 0.4), length - 0.03 - a);
      if (Uniform(rng, 0, 1) < 0.75) {
        box(a, 0.02, z, a + w, Uniform(rng, 0.15, depth - 0.02),
            z + Uniform(rng, 0.12, 0.85 * (height - 0.1) / boards));
      }
      a += w + Uniform(rng, 0.0, 0.15);
    }
  }
}

void AddPlant(Scene& s, std::mt19937_64& rng, const Vec3& b) {
  const double r = Uniform(rng, 0.15, 0.25);
  s.cylinders.push_back({b, r, 0.4});
  const double f = Uniform(rng, 0.3, 0.5);
  s.media.push_back({b + Vec3(0, 0, 0.4 + 1.2 * f), Vec3(f, f, 1.3 * f), 0.12, false});
}

}  // namespace ctlio::sim::content
