// The quad world's park furnished like a real college garden (docs/experiments/worlds-geometry.md,
// "The open park"): a rim of stone walls with buildings behind, lamps, benches, bins and clipped
// low hedges along the path, and a mound in the lawn. Without them a 64-beam head on the open lawn
// saw upright structure within 30 m in 2–5 of 12 azimuth sectors (the real Newer College
// keyframes: 12 of 12), half its rays went to the sky, and a point-to-point ICP there drifted 2–8
// times the real pairs' error.
#pragma once

#include <cstdint>

#include "ctlio/sim/geometry.h"
#include "ctlio/sim/guided_motion.h"

namespace ctlio::sim {

struct ParkBounds {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;  // the lawn; the rim stands outside it
};

// Adds the park's furniture to `s`, drawn from its own generator (seeded by `seed`), so the rest of
// the quad world is the same with or without it. Everything stays clear of `path` and of the
// lanes of the walking people already in `s.movers`; the west side (the quad's east range) gets
// no rim.
void FurnishPark(Scene& s, const Path& path, const ParkBounds& park, uint64_t seed);

}  // namespace ctlio::sim
