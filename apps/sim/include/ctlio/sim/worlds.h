// The simulated worlds (docs/user-guide/simulator.md). Each is a pure function of
// WorldConfig::seed and the documented parameters below: the geometry (a Scene of solid
// primitives) and a closed guide path at floor level that the motion follows (guided_motion.h).
// Random draws use one mt19937_64 seeded by std::seed_seq{seed, kind} in a fixed order, and
// uniform numbers from the top 53 bits, so a world is the same on every platform.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include "ctlio/sim/geometry.h"
#include "ctlio/sim/guided_motion.h"

namespace ctlio::sim {

enum class WorldKind { kBox, kStreet, kCorridor, kPark, kIndoor, kQuad, kTown, kOffice };
const char* WorldName(WorldKind w);
// box | street | corridor | park | indoor | quad | town | office
WorldKind ParseWorld(const std::string& name);

struct Range {
  double lo = 0.0, hi = 0.0;
};

// The box room of SPEC §6 (the default world).
struct RoomConfig {
  Vec3 min = Vec3(-50, -50, 0);  // walls x, y ∈ [−50, 50], floor 0, ceiling 10
  Vec3 max = Vec3(50, 50, 10);
  std::vector<Box> obstacles;    // optional interior boxes / pillars
  double path_half_size = 30.0;  // guide path (walking/vehicle): square of ±30 m, corners 20 m
};

// Street canyon: a rectangular loop of streets around one block (the vehicle turns at the four
// corners). Façades line both sides of every street: buildings of random width, setback, depth
// and height with random gaps; parked cars at the kerb, poles and trees (trunk + crown sphere) on
// the pavement. The path drives on the right-hand lane. Open intersections at the corners.
struct StreetParams {
  double length = 400.0;         // long sides of the loop [m] (centreline)
  double width = 120.0;          // short sides [m]
  double road_half_width = 7.0;  // kerb at ±7 m from the road centre
  double pavement = 3.0;         // kerb → building line [m]
  double lane_offset = 2.0;      // path to the right of the road centre [m]
  double corner_radius = 12.0;   // path rounding at the corners [m]
  double corner_clear = 22.0;    // no façade within this distance of an intersection centre
  Range building_width{8, 25}, building_depth{8, 15}, building_height{6, 30}, setback{0, 3};
  double gap_probability = 0.25;  // a gap after a building, of width gap_width
  Range gap_width{3, 10};
  double car_probability = 0.5;  // per 6 m kerb slot
  Range pole_spacing{20, 35}, tree_spacing{12, 25};
};

// Corridor / tunnel: a rectangular ring of one smooth corridor (constant cross-section, no
// features) of `width` × `height`; the path follows its axis and starts at the beginning of a
// long straight. Along the axis only the far end of the straight (40–150 m ahead and behind,
// a few dozen returns of the near-horizontal beams) constrains translation.
struct CorridorParams {
  double length = 150.0;  // long straights [m] (centreline)
  double loop_width = 30.0;
  double width = 3.0, height = 3.0, wall = 0.3;
  double corner_radius = 1.2;
};

// Park / open field: bilinear height field (sum of four random sinusoidal hills sampled on a
// `cell` grid) with sparse trees and benches, none within `clearance` of the path (an oval loop).
struct ParkParams {
  double loop_x = 140.0, loop_y = 80.0, corner_radius = 30.0;
  double extent = 320.0;        // the field covers ±extent in x and y [m]
  double cell = 1.0;            // height-field cell [m]
  double hill_amplitude = 0.6;  // amplitude of each of the four sinusoids [m]
  Range hill_wavelength{25, 90};
  double trees_per_hectare = 6.0, benches_per_hectare = 2.0;
  double clearance = 4.0;  // free band around the path [m]
};

// Multi-level indoor: two storeys of rooms in a row (enfilade: partition walls with a door on
// the path), ground floor along y = depth/2, upper floor in a parallel strip; two stair halls at
// the ends with a straight flight each. The path goes east through the ground-floor rooms, up
// the east flight, west through the upper rooms and down the west flight. Tables in the rooms.
struct IndoorParams {
  int rooms = 4;  // per storey
  Range room_length{5, 9};
  double depth = 8.0, storey = 3.0, slab = 0.2, wall = 0.15;
  double door_width = 1.2, door_height = 2.1;
  double hall_length = 6.0, stair_run = 5.0, stair_width = 2.0;
  int steps = 16;
  int tables_per_room = 2;
};

// The realistic worlds (docs/user-guide/simulator.md, "Realistic content"; built from
// src/world_content.h): façades with windows (recesses, glass returning nothing), ledges,
// balconies and doors; trees and bushes whose crowns are scattering media; hedges; grass as a
// scattering layer over a ground with micro-relief; parked cars, poles, people (standing, and
// walking back and forth on lanes clear of the path), benches; furniture.
// Free paths are the mean depth of a return inside a medium.
struct VegetationParams {
  double crown_free_path = 0.8;  // tree crowns [m]
  double bush_free_path = 0.5;
  double hedge_free_path = 0.35;
  double grass_height = 0.1;      // [m]
  double grass_free_path = 0.08;  // [m]
  double relief = 0.03;           // ground micro-relief amplitude [m] (0.6 m lattice)
  double grass_relief = 0.04;     // extra relief under grass [m] (tussocks, 0.25 m lattice)
};

// College quad (Newer College-like): a lawn of lawn_x × lawn_y inside a ring of stone buildings
// (3–4 storeys, windows), a walkway of `walkway` between lawn and façades, an arch through the
// east range into a park (trees, bushes, hedges, benches) of park × park. The path goes round the
// quad on the walkway, through the arch, round the park and back.
struct QuadParams {
  double lawn_x = 48.0, lawn_y = 36.0, walkway = 4.0;
  Range depth{9, 13};     // building depth [m]
  Range segment{14, 30};  // length of one building along a side [m]
  double storey = 3.6;
  double arch_width = 5.0, arch_height = 4.2;
  double park = 90.0, park_gap = 6.0;  // park side; distance east of the east range
  double park_trees_per_hectare = 30.0, park_bushes_per_hectare = 20.0;
  int quad_trees = 4, people = 8, benches = 6;
  int walkers = 8;  // moving people: half on the lawn, half in the park
  VegetationParams vegetation;
};

// Town street (KITTI-like): a rectangular loop of streets (length × width centreline) around one
// block, with kerbs and raised pavements, rows of houses (2–5 storeys, windows, balconies) behind
// front gardens (grass, hedges, bushes, trees), street trees at the kerb, parked cars on both
// sides, poles and signs, people on the pavements. The vehicle drives on the right-hand lane.
struct TownParams {
  double length = 300.0, width = 110.0;
  double road_half_width = 5.5, pavement = 3.0, lane_offset = 1.8;
  double corner_radius = 10.0, corner_clear = 9.5;
  Range garden{2, 9};  // pavement → façade [m]
  Range house_width{9, 20}, house_depth{9, 14}, gap{1, 7};
  int min_storeys = 2, max_storeys = 5;
  double hedge_probability = 0.85;   // per house: a hedge along the pavement
  Range street_tree_spacing{5, 10};  // at the kerb [m]
  double car_probability = 0.65;     // per 6 m kerb slot
  Range pole_spacing{18, 30};
  double people_per_100m = 3.0;
  double walkers_per_100m = 1.0;  // moving people, per side of a street
  VegetationParams vegetation;
};

// Office floor: an open-plan floor of size_x × size_y × height with windows along both long walls,
// a central core (meeting rooms) lined with shelves, desk rows with chairs, monitors and screens
// between the path loop and the windows, shelves and cabinets on the end walls, columns, plants
// and ceiling lamps. The path loops round the core.
struct OfficeParams {
  double size_x = 40.0, size_y = 24.0, height = 3.0;
  double core_x = 16.0, core_y = 6.0;  // central block
  double aisle = 2.4;                  // free band the path runs in, around the core
  int plants = 8;
};

// The box room is SimConfig::room (it predates the other worlds).
struct WorldConfig {
  WorldKind kind = WorldKind::kBox;
  uint64_t seed = 2403059680ULL;  // kExperimentSeed: the same world for every sequence
  StreetParams street;
  CorridorParams corridor;
  ParkParams park;
  IndoorParams indoor;
  QuadParams quad;
  TownParams town;
  OfficeParams office;
};

struct World {
  Scene scene;               // for the box world: its walls as solids (casting uses the room)
  Path path;                 // closed guide path at floor level
  double start_range = 0.0;  // sequences start at arc length U(0, start_range)
  double max_speed = 50.0;   // fastest carrier the path's corners and clearances allow [m/s]
};

World BuildWorld(const WorldConfig& config, const RoomConfig& room);

// Parts of BuildWorld, one per kind.
World BuildBoxWorld(const RoomConfig& room);
World BuildStreetWorld(const StreetParams& p, uint64_t seed);
World BuildCorridorWorld(const CorridorParams& p);
World BuildParkWorld(const ParkParams& p, uint64_t seed);
World BuildIndoorWorld(const IndoorParams& p, uint64_t seed);
World BuildQuadWorld(const QuadParams& p, uint64_t seed);
World BuildTownWorld(const TownParams& p, uint64_t seed);
World BuildOfficeWorld(const OfficeParams& p, uint64_t seed);

// The generator of a world's random draws: mt19937_64 over std::seed_seq{seed, kind}.
std::mt19937_64 WorldRandom(uint64_t seed, WorldKind kind);

// Top view (SVG) of a world: solids by height, the height field as contour shading, the path.
void WriteTopViewSvg(const World& world, const std::string& file, const std::string& title);

}  // namespace ctlio::sim
