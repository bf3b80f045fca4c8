#include "ctlio/sim/worlds.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>

#include "ctlio/sim/random_draw.h"

namespace ctlio::sim {
namespace {

// The rectangle (0, 0)–(lx, ly) grown by `offset` on every side, counter-clockwise.
std::vector<Vec3> Rectangle(double lx, double ly, double offset, double z = 0.0) {
  return {Vec3(-offset, -offset, z), Vec3(lx + offset, -offset, z),
          Vec3(lx + offset, ly + offset, z), Vec3(-offset, ly + offset, z)};
}

Box Span(const Vec3& a, const Vec3& b) { return Box::Spanning(a, b); }

}  // namespace

std::mt19937_64 WorldRandom(uint64_t seed, WorldKind kind) {
  std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(kind), 0x3017u};
  return std::mt19937_64(seq);
}

const char* WorldName(WorldKind w) {
  switch (w) {
    case WorldKind::kBox:
      return "box";
    case WorldKind::kStreet:
      return "street";
    case WorldKind::kCorridor:
      return "corridor";
    case WorldKind::kPark:
      return "park";
    case WorldKind::kIndoor:
      return "indoor";
    case WorldKind::kQuad:
      return "quad";
    case WorldKind::kTown:
      return "town";
    case WorldKind::kOffice:
      return "office";
  }
  return "?";
}

WorldKind ParseWorld(const std::string& name) {
  for (WorldKind w : {WorldKind::kBox, WorldKind::kStreet, WorldKind::kCorridor, WorldKind::kPark,
                      WorldKind::kIndoor, WorldKind::kQuad, WorldKind::kTown, WorldKind::kOffice}) {
    if (name == WorldName(w)) return w;
  }
  throw std::runtime_error(
      "unknown world '" + name +
      "' (expected box, street, corridor, park, indoor, quad, town or office)");
}

World BuildWorld(const WorldConfig& c, const RoomConfig& room) {
  switch (c.kind) {
    case WorldKind::kBox:
      return BuildBoxWorld(room);
    case WorldKind::kStreet:
      return BuildStreetWorld(c.street, c.seed);
    case WorldKind::kCorridor:
      return BuildCorridorWorld(c.corridor);
    case WorldKind::kPark:
      return BuildParkWorld(c.park, c.seed);
    case WorldKind::kIndoor:
      return BuildIndoorWorld(c.indoor, c.seed);
    case WorldKind::kQuad:
      return BuildQuadWorld(c.quad, c.seed);
    case WorldKind::kTown:
      return BuildTownWorld(c.town, c.seed);
    case WorldKind::kOffice:
      return BuildOfficeWorld(c.office, c.seed);
  }
  throw std::runtime_error("BuildWorld: unknown kind");
}

World BuildBoxWorld(const RoomConfig& room) {
  World w;
  w.scene.floors = {room.min.z()};
  w.scene.ceilings = {room.max.z()};
  const Vec3 t(1, 1, 0);  // wall thickness outside the room
  const Vec3 lo = room.min, hi = room.max;
  w.scene.boxes = {Span(lo - t, Vec3(lo.x(), hi.y() + 1, hi.z())),
                   Span(Vec3(hi.x(), lo.y() - 1, lo.z()), hi + t),
                   Span(lo - t, Vec3(hi.x() + 1, lo.y(), hi.z())),
                   Span(Vec3(lo.x() - 1, hi.y(), lo.z()), hi + t)};
  for (const Box& b : room.obstacles) w.scene.boxes.push_back(b);
  w.scene.Build(4.0);
  const double h = room.path_half_size;
  w.path =
      Path({Vec3(-h, -h, lo.z()), Vec3(h, -h, lo.z()), Vec3(h, h, lo.z()), Vec3(-h, h, lo.z())},
           20.0, 0.5);
  w.start_range = w.path.Length();
  return w;
}

World BuildStreetWorld(const StreetParams& p, uint64_t seed) {
  std::mt19937_64 rng = WorldRandom(seed, WorldKind::kStreet);
  auto U = [&](const Range& r) { return Uniform(rng, r.lo, r.hi); };
  World w;
  Scene& s = w.scene;
  s.floors = {0.0};
  const std::vector<Vec3> road = Rectangle(p.length, p.width, 0.0);
  for (int side = 0; side < 4; ++side) {
    const Vec3 A = road[side], B = road[(side + 1) % 4];
    const double len = (B - A).norm();
    const Vec3 u = (B - A) / len;
    const Vec3 out(u.y(), -u.x(), 0.0);  // right of the travel direction: outside the block
    for (const double sign : {1.0, -1.0}) {
      const Vec3 n = sign * out;
      auto at = [&](double along, double lateral, double z) -> Vec3 {
        return A + along * u + lateral * n + Vec3(0, 0, z);
      };
      // Façades: buildings and gaps.
      const double line = p.road_half_width + p.pavement;
      for (double a = p.corner_clear; a < len - p.corner_clear - 4.0;) {
        const double width = std::min(U(p.building_width), len - p.corner_clear - a);
        const double set = U(p.setback), depth = U(p.building_depth), height = U(p.building_height);
        s.boxes.push_back(Span(at(a, line + set, 0.0), at(a + width, line + set + depth, height)));
        a += width;
        if (Uniform(rng, 0, 1) < p.gap_probability) a += U(p.gap_width);
      }
      // Parked cars in 6 m kerb slots.
      for (double a = p.corner_clear; a + 6.0 < len - p.corner_clear; a += 6.0) {
        if (Uniform(rng, 0, 1) >= p.car_probability) continue;
        const double height = Uniform(rng, 1.4, 1.7);
        s.boxes.push_back(Span(at(a + 0.8, p.road_half_width - 2.1, 0.0),
                               at(a + 5.2, p.road_half_width - 0.3, height)));
      }
      // Poles at the kerb, trees on the pavement.
      for (double a = p.corner_clear + U(p.pole_spacing) / 2; a < len - p.corner_clear;
           a += U(p.pole_spacing)) {
        s.cylinders.push_back({at(a, p.road_half_width + 0.5, 0.0), 0.12, Uniform(rng, 6, 8)});
      }
      for (double a = p.corner_clear + U(p.tree_spacing) / 2; a < len - p.corner_clear;
           a += U(p.tree_spacing)) {
        const double trunk = Uniform(rng, 2.5, 4.0), crown = Uniform(rng, 1.5, 2.5);
        const Vec3 base = at(a, p.road_half_width + 1.8, 0.0);
        s.cylinders.push_back({base, Uniform(rng, 0.15, 0.3), trunk + 0.5 * crown});
        s.spheres.push_back({base + Vec3(0, 0, trunk + 0.5 * crown), crown});
      }
    }
  }
  s.Build(4.0);
  w.path = Path(Rectangle(p.length, p.width, p.lane_offset), p.corner_radius, 0.5);
  w.start_range = w.path.Length();
  w.max_speed = 20.0;
  return w;
}

World BuildCorridorWorld(const CorridorParams& p) {
  World w;
  Scene& s = w.scene;
  s.floors = {0.0};
  s.ceilings = {p.height};
  const double h = 0.5 * p.width, L = p.length, W = p.loop_width, t = p.wall;
  // Outer ring of walls (outside the centreline by h) and inner ring (inside by h).
  s.boxes = {Span(Vec3(-h - t, -h - t, 0), Vec3(L + h + t, -h, p.height)),
             Span(Vec3(-h - t, W + h, 0), Vec3(L + h + t, W + h + t, p.height)),
             Span(Vec3(-h - t, -h, 0), Vec3(-h, W + h, p.height)),
             Span(Vec3(L + h, -h, 0), Vec3(L + h + t, W + h, p.height)),
             Span(Vec3(h, h, 0), Vec3(L - h, h + t, p.height)),
             Span(Vec3(h, W - h - t, 0), Vec3(L - h, W - h, p.height)),
             Span(Vec3(h, h, 0), Vec3(h + t, W - h, p.height)),
             Span(Vec3(L - h - t, h, 0), Vec3(L - h, W - h, p.height))};
  s.Build(2.0);
  w.path = Path(Rectangle(L, W, 0.0), p.corner_radius, 0.5);
  w.start_range = 10.0;
  w.max_speed = 3.0;
  return w;
}

void WriteTopViewSvg(const World& world, const std::string& file, const std::string& title) {
  const Scene& s = world.scene;
  Box view{Vec3::Constant(1e300), Vec3::Constant(-1e300)};
  for (const Vec3& q : world.path.ControlPoints()) {
    view.min = view.min.cwiseMin(q);
    view.max = view.max.cwiseMax(q);
  }
  const Vec3 margin = Vec3(5, 5, 0) + 0.15 * (view.max - view.min).cwiseProduct(Vec3(1, 1, 0));
  view.min -= margin;
  view.max += margin;
  const double size = std::max(view.max.x() - view.min.x(), view.max.y() - view.min.y());
  const double px = 640.0 / size;
  auto X = [&](double x) { return (x - view.min.x()) * px; };
  auto Y = [&](double y) { return (view.max.y() - y) * px; };
  const double wpx = (view.max.x() - view.min.x()) * px, hpx = (view.max.y() - view.min.y()) * px;
  std::ofstream out(file);
  if (!out) throw std::runtime_error(file + ": cannot write");
  out.precision(4);
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << wpx << "' height='" << hpx + 24
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
         "fill='#f4f1e8'/>\n";
  // Height field: cells of ~18 px, shaded by height.
  for (const HeightField& f : s.fields) {
    const int step = std::max(1, int(std::ceil(18.0 / (f.cell * px))));
    double lo = 1e300, hi = -1e300;
    for (double z : f.z) lo = std::min(lo, z), hi = std::max(hi, z);
    for (int j = 0; j + step <= f.ny; j += step) {
      for (int i = 0; i + step <= f.nx; i += step) {
        const double x = f.x0 + i * f.cell, y = f.y0 + j * f.cell, e = step * f.cell;
        if (x + e < view.min.x() || x > view.max.x() || y + e < view.min.y() || y > view.max.y())
          continue;
        const int g = int(150 + 90 * (f.Node(i, j) - lo) / std::max(hi - lo, 1e-9));
        out << "<rect x='" << X(x) << "' y='" << Y(y + e) << "' width='" << e * px + 0.5
            << "' height='" << e * px + 0.5 << "' fill='rgb(" << g / 2 << ',' << g << ',' << g / 2
            << ")'/>\n";
      }
    }
  }
  for (const GroundCover& c : s.covers) {  // grass
    if (c.x1 < view.min.x() || c.x0 > view.max.x() || c.y1 < view.min.y() || c.y0 > view.max.y())
      continue;
    out << "<rect x='" << X(c.x0) << "' y='" << Y(c.y1) << "' width='" << (c.x1 - c.x0) * px
        << "' height='" << (c.y1 - c.y0) * px << "' fill='#b8d8a0'/>\n";
  }
  std::vector<Box> boxes = s.boxes;
  std::sort(boxes.begin(), boxes.end(),
            [](const Box& a, const Box& b) { return a.max.z() < b.max.z(); });
  auto visible = [&](const Vec3& lo, const Vec3& hi) {
    return hi.x() > view.min.x() && lo.x() < view.max.x() && hi.y() > view.min.y() &&
           lo.y() < view.max.y();
  };
  // Worlds of thousands of façade parts: the small ones (piers, bands, < 1 m² from above) are
  // left out, the building bodies show.
  const bool detailed = boxes.size() > 2000;
  for (const Box& b : boxes) {
    if (!visible(b.min, b.max)) continue;
    if (detailed && (b.max.x() - b.min.x()) * (b.max.y() - b.min.y()) < 1.0) continue;
    const int g = std::clamp(int(200 - 4 * b.max.z()), 60, 200);
    out << "<rect x='" << X(b.min.x()) << "' y='" << Y(b.max.y()) << "' width='"
        << (b.max.x() - b.min.x()) * px << "' height='" << (b.max.y() - b.min.y()) * px
        << "' fill='rgb(" << g << ',' << g << ',' << g + 20
        << ")' fill-opacity='0.6' stroke='#333' stroke-width='0.3'/>\n";
  }
  for (const Box& b : s.glass) {
    if (!visible(b.min, b.max) || detailed) continue;
    out << "<rect x='" << X(b.min.x()) << "' y='" << Y(b.max.y()) << "' width='"
        << std::max((b.max.x() - b.min.x()) * px, 0.8) << "' height='"
        << std::max((b.max.y() - b.min.y()) * px, 0.8) << "' fill='#3080e0'/>\n";
  }
  for (const Medium& m : s.media) {  // foliage
    if (!visible(m.centre, m.centre)) continue;
    if (m.box) {
      out << "<rect x='" << X(m.centre.x() - m.radii.x()) << "' y='"
          << Y(m.centre.y() + m.radii.y()) << "' width='" << 2 * m.radii.x() * px << "' height='"
          << 2 * m.radii.y() * px << "' fill='#2f6f2f' fill-opacity='0.7'/>\n";
    } else {
      out << "<ellipse cx='" << X(m.centre.x()) << "' cy='" << Y(m.centre.y()) << "' rx='"
          << m.radii.x() * px << "' ry='" << m.radii.y() * px
          << "' fill='#3a7d3a' fill-opacity='0.45'/>\n";
    }
  }
  for (const Sphere& c : s.spheres) {
    if (!visible(c.centre, c.centre)) continue;
    out << "<circle cx='" << X(c.centre.x()) << "' cy='" << Y(c.centre.y()) << "' r='"
        << c.radius * px << "' fill='#3a7d3a' fill-opacity='0.6'/>\n";
  }
  for (const Cylinder& c : s.cylinders) {
    if (!visible(c.base, c.base)) continue;
    out << "<circle cx='" << X(c.base.x()) << "' cy='" << Y(c.base.y()) << "' r='"
        << std::max(c.radius * px, 0.8) << "' fill='#5a3a1a'/>\n";
  }
  out << "<polygon fill='none' stroke='#d02020' stroke-width='1.2' points='";
  const auto& path = world.path.ControlPoints();
  for (size_t i = 0; i < path.size(); i += 4) out << X(path[i].x()) << ',' << Y(path[i].y()) << ' ';
  const double scale = size > 150 ? 50.0 : 10.0;
  out << "'/>\n<line x1='10' y1='" << hpx + 12 << "' x2='" << 10 + scale * px << "' y2='"
      << hpx + 12 << "' stroke='black' stroke-width='2'/>\n<text x='" << 16 + scale * px << "' y='"
      << hpx + 16 << "'>" << scale << " m   " << title << " (path in red)</text>\n</svg>\n";
}

}  // namespace ctlio::sim
