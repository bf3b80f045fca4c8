#include "ctlio/sim/geometry.h"

#include <algorithm>
#include <cmath>

namespace ctlio::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Parameter interval of the ray inside the xy rectangle [lo, hi]; empty when t0 > t1.
void ClipXY(const Vec3& o, const Vec3& d, double lx, double ly, double hx, double hy, double* t0,
            double* t1) {
  const double lo[2] = {lx, ly}, hi[2] = {hx, hy};
  for (int i = 0; i < 2; ++i) {
    if (d[i] == 0.0) {
      if (o[i] < lo[i] || o[i] > hi[i]) *t0 = kInf;
      continue;
    }
    double a = (lo[i] - o[i]) / d[i], b = (hi[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    *t0 = std::max(*t0, a);
    *t1 = std::min(*t1, b);
  }
}

// Restricts [t0, t1] to where the ray's z lies in [z_lo, z_hi].
void ClipZ(const Vec3& o, const Vec3& d, double z_lo, double z_hi, double* t0, double* t1) {
  if (d.z() == 0.0) {
    if (o.z() < z_lo || o.z() > z_hi) *t0 = kInf;
    return;
  }
  double a = (z_lo - o.z()) / d.z(), b = (z_hi - o.z()) / d.z();
  if (a > b) std::swap(a, b);
  *t0 = std::max(*t0, a);
  *t1 = std::min(*t1, b);
}

// 2-D DDA (Amanatides & Woo) over square cells of a grid with origin (x0, y0): calls
// visit(i, j, t_enter, t_exit) for the cells the ray crosses in [t0, t1], in order, until visit
// returns true.
template <class Visit>
void TraverseGrid(double x0, double y0, double cell, int nx, int ny, const Vec3& o, const Vec3& d,
                  double t0, double t1, Visit visit) {
  if (!(t0 < t1)) return;
  const Vec3 p = o + t0 * d;
  int i = std::clamp(int(std::floor((p.x() - x0) / cell)), 0, nx - 1);
  int j = std::clamp(int(std::floor((p.y() - y0) / cell)), 0, ny - 1);
  const int si = d.x() > 0 ? 1 : -1, sj = d.y() > 0 ? 1 : -1;
  const double dtx = d.x() != 0.0 ? cell / std::abs(d.x()) : kInf;
  const double dty = d.y() != 0.0 ? cell / std::abs(d.y()) : kInf;
  double tx = d.x() != 0.0 ? (x0 + (i + (si > 0)) * cell - o.x()) / d.x() : kInf;
  double ty = d.y() != 0.0 ? (y0 + (j + (sj > 0)) * cell - o.y()) / d.y() : kInf;
  double t = t0;
  while (t < t1) {
    const double t_exit = std::min({tx, ty, t1});
    if (visit(i, j, t, t_exit)) return;
    t = t_exit;
    if (tx <= ty) {
      i += si;
      tx += dtx;
    } else {
      j += sj;
      ty += dty;
    }
    if (i < 0 || j < 0 || i >= nx || j >= ny) return;
  }
}

// Smallest root s ∈ [0, len] of A s² + B s + C where the function goes from positive to
// non-positive (the ray enters the solid); NaN when none.
double EnteringRoot(double A, double B, double C, double len) {
  auto entering = [&](double s) { return s >= 0.0 && s <= len && 2 * A * s + B <= 0.0; };
  if (C < 0.0) return NAN;  // starts below
  if (C == 0.0) return B <= 0.0 ? 0.0 : NAN;
  if (std::abs(A) <= 1e-15 * (std::abs(B) + std::abs(C))) {
    const double s = -C / B;
    return B < 0.0 && s <= len ? s : NAN;
  }
  const double disc = B * B - 4 * A * C;
  if (disc < 0.0) return NAN;
  const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  double r1 = q / A, r2 = q != 0.0 ? C / q : NAN;
  if (r1 > r2) std::swap(r1, r2);
  if (entering(r1)) return r1;
  if (entering(r2)) return r2;
  return NAN;
}

}  // namespace

double HeightField::Height(double x, double y) const {
  const double a = (x - x0) / cell, b = (y - y0) / cell;
  if (a < 0 || b < 0 || a > nx || b > ny) return NAN;
  const int i = std::min(int(a), nx - 1), j = std::min(int(b), ny - 1);
  const double u = a - i, v = b - j;
  return Node(i, j) * (1 - u) * (1 - v) + Node(i + 1, j) * u * (1 - v) +
         Node(i, j + 1) * (1 - u) * v + Node(i + 1, j + 1) * u * v;
}

void HeightField::UpdateTop() {
  top = z.empty() ? -kInf : *std::max_element(z.begin(), z.end());
  const int nbx = (nx + kBlock - 1) / kBlock, nby = (ny + kBlock - 1) / kBlock;
  block_top.assign(size_t(std::max(nbx, 0)) * size_t(std::max(nby, 0)), -kInf);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      // A node bounds the cells on both sides of a block edge.
      for (int bj = std::max(0, (j - 1) / kBlock); bj <= std::min(nby - 1, j / kBlock); ++bj) {
        for (int bi = std::max(0, (i - 1) / kBlock); bi <= std::min(nbx - 1, i / kBlock); ++bi) {
          double& t = block_top[size_t(bj) * nbx + bi];
          t = std::max(t, Node(i, j));
        }
      }
    }
  }
}

RayHit IntersectBox(const Box& b, const Vec3& o, const Vec3& d, double t_max) {
  return IntersectBox(b, o, d, d.cwiseInverse(), t_max);
}

RayHit IntersectBox(const Box& b, const Vec3& o, const Vec3& d, const Vec3& inv_d, double t_max) {
  double t0 = 0.0, t1 = t_max;
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (o[i] < b.min[i] || o[i] > b.max[i]) return {};
      continue;
    }
    double a = (b.min[i] - o[i]) * inv_d[i], c = (b.max[i] - o[i]) * inv_d[i];
    if (a > c) std::swap(a, c);
    if (a > t0) {
      t0 = a;
      axis = i;
    }
    t1 = std::min(t1, c);
    if (t0 > t1) return {};
  }
  if (axis < 0 || t0 >= t_max) return {};  // starts inside (or no entry face)
  RayHit h;
  h.t = t0;
  h.normal[axis] = d[axis] > 0 ? -1.0 : 1.0;
  return h;
}

RayHit IntersectCylinder(const Cylinder& c, const Vec3& o, const Vec3& d, double t_max) {
  RayHit best;
  const double z0 = c.base.z(), z1 = c.base.z() + c.height;
  const double ox = o.x() - c.base.x(), oy = o.y() - c.base.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  const double bh = ox * d.x() + oy * d.y();
  const double cc = ox * ox + oy * oy - c.radius * c.radius;
  if (a > 0.0 && cc > 0.0) {  // outside the infinite cylinder: side entry
    const double disc = bh * bh - a * cc;
    if (disc >= 0.0) {
      const double t = (-bh - std::sqrt(disc)) / a;
      const double z = o.z() + t * d.z();
      if (t > 0.0 && t < t_max && z >= z0 && z <= z1) {
        best.t = t;
        best.normal = Vec3(ox + t * d.x(), oy + t * d.y(), 0.0) / c.radius;
      }
    }
  }
  // Caps: the top seen from above, the bottom from below.
  for (const double zc : {z1, z0}) {
    const bool top = zc == z1;
    if (d.z() == 0.0 || (top ? !(d.z() < 0 && o.z() > zc) : !(d.z() > 0 && o.z() < zc))) continue;
    const double t = (zc - o.z()) / d.z();
    const double x = ox + t * d.x(), y = oy + t * d.y();
    if (t > 0.0 && t < std::min(t_max, best.t) && x * x + y * y <= c.radius * c.radius) {
      best.t = t;
      best.normal = Vec3(0, 0, top ? 1.0 : -1.0);
    }
  }
  return best;
}

RayHit IntersectSphere(const Sphere& s, const Vec3& o, const Vec3& d, double t_max) {
  const Vec3 oc = o - s.centre;
  const double b = oc.dot(d), c = oc.squaredNorm() - s.radius * s.radius;
  if (c <= 0.0) return {};  // inside
  const double disc = b * b - c;
  if (disc < 0.0) return {};
  const double t = -b - std::sqrt(disc);
  if (!(t > 0.0 && t < t_max)) return {};
  RayHit h;
  h.t = t;
  h.normal = (oc + t * d) / s.radius;
  return h;
}

RayHit IntersectHeightField(const HeightField& f, const Vec3& o, const Vec3& d, double t_max) {
  if (f.nx < 1 || f.ny < 1) return {};
  double t0 = 0.0, t1 = t_max;
  ClipXY(o, d, f.x0, f.y0, f.x0 + f.nx * f.cell, f.y0 + f.ny * f.cell, &t0, &t1);
  ClipZ(o, d, -kInf, f.top, &t0, &t1);
  const double t_first = t0;
  RayHit hit;
  auto cell = [&](int i, int j, double ta, double tb) {
    const double h00 = f.Node(i, j), h10 = f.Node(i + 1, j), h01 = f.Node(i, j + 1),
                 h11 = f.Node(i + 1, j + 1);
    const double za = o.z() + ta * d.z(), zb = o.z() + tb * d.z();
    if (std::min(za, zb) > std::max({h00, h10, h01, h11})) return false;
    // Cell coordinates a, b ∈ [0, 1] along the ray, s = t − ta.
    const double aa = (o.x() + ta * d.x() - f.x0) / f.cell - i, a1 = d.x() / f.cell;
    const double ba = (o.y() + ta * d.y() - f.y0) / f.cell - j, b1 = d.y() / f.cell;
    const double e1 = h10 - h00, e2 = h01 - h00, k = h00 - h10 - h01 + h11;
    const double H0 = h00 + e1 * aa + e2 * ba + k * aa * ba;
    const double H1 = e1 * a1 + e2 * b1 + k * (aa * b1 + ba * a1);
    const double H2 = k * a1 * b1;
    // Below the surface at a later cell's entry: the crossing fell on the shared edge.
    const double s =
        za < H0 ? (ta > t_first ? 0.0 : NAN) : EnteringRoot(-H2, d.z() - H1, za - H0, tb - ta);
    if (std::isnan(s)) return false;
    hit.t = ta + s;
    const double a = aa + s * a1, b = ba + s * b1;
    hit.normal = Vec3(-(e1 + k * b) / f.cell, -(e2 + k * a) / f.cell, 1.0).normalized();
    return true;
  };
  // Blocks of kBlock × kBlock cells whose highest node is below the ray are skipped whole.
  const int B = HeightField::kBlock;
  const int nbx = (f.nx + B - 1) / B, nby = (f.ny + B - 1) / B;
  TraverseGrid(f.x0, f.y0, B * f.cell, nbx, nby, o, d, t0, t1,
               [&](int bi, int bj, double ta, double tb) {
                 const double za = o.z() + ta * d.z(), zb = o.z() + tb * d.z();
                 if (std::min(za, zb) > f.block_top[size_t(bj) * nbx + bi]) return false;
                 bool found = false;
                 TraverseGrid(f.x0 + bi * B * f.cell, f.y0 + bj * B * f.cell, f.cell,
                              std::min(B, f.nx - bi * B), std::min(B, f.ny - bj * B), o, d, ta, tb,
                              [&](int i, int j, double ca, double cb) {
                                return found = cell(bi * B + i, bj * B + j, ca, cb);
                              });
                 return found;
               });
  if (hit.t <= 0.0) return {};
  return hit;
}

void Scene::Build(double cell) {
  cell_ = cell;
  auto xy_bounds = [&](const Ref& r) -> Box {
    switch (r.kind) {
      case kBox:
        return boxes[r.index];
      case kCylinder: {
        const Cylinder& c = cylinders[r.index];
        const Vec3 e(c.radius, c.radius, 0.0);
        return {c.base - e, c.base + e + Vec3(0, 0, c.height)};
      }
      case kMedium:
        return {media[r.index].centre - media[r.index].radii,
                media[r.index].centre + media[r.index].radii};
      case kGlass:
        return glass[r.index];
      case kMover: {  // the lane it walks
        const Mover& m = movers[r.index];
        const Vec3 e(m.radius, m.radius, 0.0);
        return {m.a.cwiseMin(m.b) - e, m.a.cwiseMax(m.b) + e + Vec3(0, 0, m.height)};
      }
      default: {
        const Sphere& s = spheres[r.index];
        return {s.centre - Vec3::Constant(s.radius), s.centre + Vec3::Constant(s.radius)};
      }
    }
  };
  std::vector<Ref> all;
  for (uint32_t i = 0; i < boxes.size(); ++i) all.push_back({kBox, i});
  for (uint32_t i = 0; i < cylinders.size(); ++i) all.push_back({kCylinder, i});
  for (uint32_t i = 0; i < spheres.size(); ++i) all.push_back({kSphere, i});
  for (uint32_t i = 0; i < media.size(); ++i) all.push_back({kMedium, i});
  for (uint32_t i = 0; i < glass.size(); ++i) all.push_back({kGlass, i});
  for (uint32_t i = 0; i < movers.size(); ++i) all.push_back({kMover, i});
  refs_.clear();
  large_.clear();
  cell_start_.assign(1, 0);
  nx_ = ny_ = 0;
  if (all.empty()) return;
  bounds_ = {Vec3::Constant(kInf), Vec3::Constant(-kInf)};
  for (const Ref& r : all) {
    const Box b = xy_bounds(r);
    bounds_.min = bounds_.min.cwiseMin(b.min);
    bounds_.max = bounds_.max.cwiseMax(b.max);
  }
  nx_ = std::max(1, int(std::ceil((bounds_.max.x() - bounds_.min.x()) / cell_)));
  ny_ = std::max(1, int(std::ceil((bounds_.max.y() - bounds_.min.y()) / cell_)));
  auto cell_range = [&](const Box& b, int* i0, int* i1, int* j0, int* j1) {
    *i0 = std::clamp(int(std::floor((b.min.x() - bounds_.min.x()) / cell_)), 0, nx_ - 1);
    *i1 = std::clamp(int(std::floor((b.max.x() - bounds_.min.x()) / cell_)), 0, nx_ - 1);
    *j0 = std::clamp(int(std::floor((b.min.y() - bounds_.min.y()) / cell_)), 0, ny_ - 1);
    *j1 = std::clamp(int(std::floor((b.max.y() - bounds_.min.y()) / cell_)), 0, ny_ - 1);
  };
  // The few primitives spanning many cells (an indoor storey's slab, long walls) are tested once
  // per ray instead of once per cell crossed.
  auto cells = [&](const Ref& r) {
    int i0, i1, j0, j1;
    cell_range(xy_bounds(r), &i0, &i1, &j0, &j1);
    return (i1 - i0 + 1) * (j1 - j0 + 1);
  };
  std::stable_sort(all.begin(), all.end(),
                   [&](const Ref& a, const Ref& b) { return cells(a) > cells(b); });
  large_.clear();
  while (!all.empty() && large_.size() < 8 && cells(all.front()) > 64) {
    large_.push_back(all.front());
    all.erase(all.begin());
  }
  for (Ref& r : all) {
    const Box b = xy_bounds(r);
    r.zlo = b.min.z();
    r.zhi = b.max.z();
  }
  cell_top_.assign(size_t(nx_) * size_t(ny_), -kInf);
  std::vector<uint32_t> count(size_t(nx_) * size_t(ny_) + 1, 0);
  for (const Ref& r : all) {
    int i0, i1, j0, j1;
    cell_range(xy_bounds(r), &i0, &i1, &j0, &j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) ++count[size_t(j) * nx_ + i + 1];
  }
  for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
  cell_start_ = count;
  refs_.resize(count.back());
  for (const Ref& r : all) {
    int i0, i1, j0, j1;
    cell_range(xy_bounds(r), &i0, &i1, &j0, &j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        refs_[count[size_t(j) * nx_ + i]++] = r;
        cell_top_[size_t(j) * nx_ + i] = std::max(cell_top_[size_t(j) * nx_ + i], r.zhi);
      }
  }
  // Each cell's refs from the lowest up: a ray's pass through the cell stops at the first ref
  // starting above its heights there (CastAt).
  for (size_t c = 0; c + 1 < cell_start_.size(); ++c) {
    std::stable_sort(refs_.begin() + cell_start_[c], refs_.begin() + cell_start_[c + 1],
                     [](const Ref& a, const Ref& b) { return a.zlo < b.zlo; });
  }
}

RayHit Scene::IntersectRef(const Ref& r, const Vec3& o, const Vec3& d, const Vec3& inv_d,
                           double t_max, double time) const {
  switch (r.kind) {
    case kBox:
      return IntersectBox(boxes[r.index], o, d, inv_d, t_max);
    case kCylinder:
      return IntersectCylinder(cylinders[r.index], o, d, t_max);
    case kMedium:
      return IntersectMedium(r.index, o, d, inv_d, t_max);
    case kGlass:
      return IntersectBox(glass[r.index], o, d, inv_d, t_max);
    case kMover: {
      if (std::isnan(time)) return {};
      const Mover& m = movers[r.index];
      return IntersectCylinder({m.At(time), m.radius, m.height}, o, d, t_max);
    }
    default:
      return IntersectSphere(spheres[r.index], o, d, t_max);
  }
}

RayHit Scene::Cast(const Vec3& o, const Vec3& d, double t_max) const {
  return CastAt(o, d, t_max, std::numeric_limits<double>::quiet_NaN());
}

RayHit Scene::Cast(const Vec3& o, const Vec3& d, double t_max, double time) const {
  return CastAt(o, d, t_max, time);
}

RayHit Scene::CastAt(const Vec3& o, const Vec3& d, double t_max, double time) const {
  RayHit best;
  bool best_glass = false;  // the nearest hit stops the ray without a return
  auto keep = [&](const RayHit& h, bool is_glass = false) {
    if (h.t < best.t && h.t < t_max) {
      best = h;
      best_glass = is_glass;
    }
  };
  const bool plain_ground = covers.empty() && relief == 0.0;
  if (plain_ground) {
    for (const double z : floors) {
      if (d.z() < 0.0 && o.z() > z) keep({(z - o.z()) / d.z(), Vec3(0, 0, 1)});
    }
  }
  for (const double z : ceilings) {
    if (d.z() > 0.0 && o.z() < z) keep({(z - o.z()) / d.z(), Vec3(0, 0, -1)});
  }
  if (plain_ground) {
    for (const HeightField& f : fields)
      keep(IntersectHeightField(f, o, d, std::min(t_max, best.t)));
  } else {
    keep(CastGround(o, d, t_max));
  }
  const Vec3 inv_d = d.cwiseInverse();
  for (const Ref& r : large_) keep(IntersectRef(r, o, d, inv_d, best.t, time), r.kind == kGlass);
  if (refs_.empty()) return best_glass ? RayHit{} : best;
  double t0 = 0.0, t1 = std::min(t_max, best.t);
  ClipXY(o, d, bounds_.min.x(), bounds_.min.y(), bounds_.max.x(), bounds_.max.y(), &t0, &t1);
  ClipZ(o, d, bounds_.min.z(), bounds_.max.z(), &t0, &t1);
  TraverseGrid(bounds_.min.x(), bounds_.min.y(), cell_, nx_, ny_, o, d, t0, t1,
               [&](int i, int j, double ta, double tb) {
                 const size_t c = size_t(j) * nx_ + i;
                 // The ray's heights inside the cell: primitives entirely above or below them
                 // cannot be hit here (where they can, they are binned into that cell too).
                 const double za = o.z() + ta * d.z(), zb = o.z() + tb * d.z();
                 const double lo = std::min(za, zb) - 1e-9, hi = std::max(za, zb) + 1e-9;
                 if (lo > cell_top_[c]) return false;
                 for (uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
                   const Ref& r = refs_[k];
                   if (r.zlo > hi) break;  // sorted by zlo (Build)
                   if (r.zhi < lo) continue;
                   keep(IntersectRef(r, o, d, inv_d, best.t, time), r.kind == kGlass);
                 }
                 return best.t <= tb;
               });
  return best_glass ? RayHit{} : best;
}

bool Scene::Occupied(const Vec3& p) const {
  for (const double z : floors)
    if (p.z() <= z) return true;
  for (const double z : ceilings)
    if (p.z() >= z) return true;
  for (const HeightField& f : fields) {
    const double h = f.Height(p.x(), p.y());
    if (!std::isnan(h) && p.z() <= h) return true;
  }
  for (const Box& b : boxes) {
    if ((p.array() > b.min.array()).all() && (p.array() < b.max.array()).all()) return true;
  }
  for (const Cylinder& c : cylinders) {
    if ((p - c.base).head<2>().norm() < c.radius && p.z() > c.base.z() &&
        p.z() < c.base.z() + c.height)
      return true;
  }
  for (const Sphere& s : spheres) {
    if ((p - s.centre).norm() < s.radius) return true;
  }
  return false;
}

}  // namespace ctlio::sim
