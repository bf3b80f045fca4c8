// Building blocks of the realistic worlds (quad, town, office; docs/user-guide/simulator.md,
// "Realistic content"): each adds solids, scattering media and glass to a Scene, drawing its
// sizes from the world's generator in a fixed order (so a world stays a pure function of its seed).
#pragma once

#include <random>

#include "ctlio/sim/geometry.h"
#include "ctlio/sim/guided_motion.h"

namespace ctlio::sim::content {

// Horizontal distance from (x, y) to the nearest control point of the path.
double DistanceToPath(const Path& path, double x, double y);

// A tree at `base` (ground point): trunk cylinder, crown of 1–3 overlapping ellipsoids of foliage
// (medium, free path `free_path`) starting at 1.8–3.5 m; `size` scales the crown (1 ≈ 3 m radius).
// Returns the crown's horizontal radius (for clearances).
double AddTree(Scene& s, std::mt19937_64& rng, const Vec3& base, double size, double free_path);
// A bush: one foliage ellipsoid on the ground, radius ≈ `size`.
void AddBush(Scene& s, std::mt19937_64& rng, const Vec3& base, double size, double free_path);
// A hedge: a box of dense foliage over the xy rectangle [a, b] up to `height`.
void AddHedge(Scene& s, const Vec3& a, const Vec3& b, double height, double free_path);

// A building over the xy rectangle [lo, hi] (lo.z = ground), `storeys` of `storey` metres: a
// solid body inset by the window recess, and on the façades whose bit is set in `facades`
// (1 = south (y = lo.y), 2 = east, 4 = north, 8 = west) an outer wall of piers and bands with
// windows (recesses; a fraction of them glass that returns nothing), string-course ledges, a few
// balconies and doors on the ground floor.
struct FacadeStyle {
  bool cornice = true;         // a 0.3 m moulding at the top
  double recess = 0.25;        // window depth [m]
  double window_width = 1.2;   // [m]
  double window_height = 1.6;  // [m]
  double sill = 0.9;           // window bottom above the storey floor [m]
  double pier = 1.4;           // wall between windows [m]
  double glass_fraction = 0.4;
  double ledge_probability = 0.5;    // per storey line
  double balcony_probability = 0.1;  // per upper window
  double door_probability = 0.15;    // per ground-floor window
};
// The quad's stone ranges and the park's buildings behind its rim (one style, drawn per building):
// windows 0.9–1.5 × 1.4–2.0 m between 0.9–2.2 m piers, recessed 0.2–0.35 m, 20–60 % glass.
FacadeStyle CollegeFacadeStyle(std::mt19937_64& rng);
// One wall of windows in its own frame p(u, w, z) = a + u·e + w·n (u ∈ [0, L] along the wall,
// z ∈ [0, storeys·storey] above a, w outwards): piers and bands fill w ∈ [0, recess], the openings
// show what lies at w < 0 (a building's body; an office's outer wall) or glass.
struct Facade {
  Vec3 a, e, n;
  Vec3 At(double u, double w, double z) const { return a + u * e + w * n + Vec3(0, 0, z); }
};
void AddFacade(Scene& s, std::mt19937_64& rng, const Facade& facade, double length, int storeys,
               double storey, const FacadeStyle& style);
void AddBuilding(Scene& s, std::mt19937_64& rng, const Vec3& lo, const Vec3& hi, int storeys,
                 double storey, int facades, const FacadeStyle& style);

// A parked car centred at `centre` (ground), long axis along x (`along_x`) or y: body of stepped
// boxes (rounded nose and tail), a glass cabin under a solid roof, wheels.
void AddCar(Scene& s, std::mt19937_64& rng, const Vec3& centre, bool along_x);
// A street lamp or sign pole: cylinder, and a head (lamp box or sign plate).
void AddPole(Scene& s, std::mt19937_64& rng, const Vec3& base);
// A standing person: legs, torso (cylinders), head (sphere).
void AddPerson(Scene& s, std::mt19937_64& rng, const Vec3& base);
// A bench (seat, back, legs) with its long axis along x or y.
void AddBench(Scene& s, const Vec3& centre, bool along_x);

// Office furniture, `base` on the floor: a desk (top, two side panels), a chair, a shelf
// (frame, boards and rows of books of random size), a potted plant (pot and foliage).
void AddDesk(Scene& s, std::mt19937_64& rng, const Vec3& base, bool along_x);
void AddChair(Scene& s, std::mt19937_64& rng, const Vec3& base);
void AddShelf(Scene& s, std::mt19937_64& rng, const Vec3& base, double length, bool along_x,
              bool facing_positive);
void AddPlant(Scene& s, std::mt19937_64& rng, const Vec3& base);

}  // namespace ctlio::sim::content
