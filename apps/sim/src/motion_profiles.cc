// Motion draws of the regimes (SPEC §6 and the walking/vehicle regimes), the experiment's
// sequence configurations and the IMU-outage list syntax (documented in lidar_inertial_sim.h).
#include <random>
#include <sstream>
#include <stdexcept>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/random_draw.h"

namespace ctlio::sim {

const char* RegimeName(Regime r) {
  switch (r) {
    case Regime::kSlow:
      return "slow";
    case Regime::kMedium:
      return "medium";
    case Regime::kFast:
      return "fast";
    case Regime::kWalking:
      return "walking";
    case Regime::kVehicle:
      return "vehicle";
  }
  return "?";
}

Regime ParseRegime(const std::string& name) {
  if (name == "slow") return Regime::kSlow;
  if (name == "medium") return Regime::kMedium;
  if (name == "fast") return Regime::kFast;
  if (name == "walking") return Regime::kWalking;
  if (name == "vehicle") return Regime::kVehicle;
  throw std::runtime_error("unknown regime '" + name +
                           "' (expected slow, medium, fast, walking or vehicle)");
}

namespace {

// Walking and vehicle draws, documented at DrawMotion.
MotionProfile DrawGuidedMotion(Regime regime, int index, uint64_t seed) {
  std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(regime), uint32_t(index)};
  std::mt19937_64 rng(seq);
  auto U = [&](double lo, double hi) { return Uniform(rng, lo, hi); };
  MotionProfile m;
  m.guided = true;
  GuideProfile& g = m.guide;
  g.start_fraction = U(0, 1);
  if (regime == Regime::kWalking) {
    g.speed = U(1.2, 1.6);
    const double f = U(1.7, 2.1);
    g.vertical = {U(0.02, 0.04), f};
    g.lateral = {U(0.02, 0.04), f / 2};
    g.speed_wave = {U(0.05, 0.15), f};
    g.yaw_slow.amplitude = U(0.2, 0.5);
    g.yaw_slow.frequency = U(0.1, 0.3);
    g.yaw_fast.amplitude = U(0.05, 0.15);
    g.yaw_fast.frequency = U(0.5, 1.0);
    g.pitch = {U(0.03, 0.08), f};
    g.roll = {U(0.02, 0.05), f / 2};
    g.height = 1.6;
    g.ramp_s = 1.0;
  } else {
    g.speed = U(8.0, 14.0);
    g.speed_wave.amplitude = U(0.5, 1.5);
    g.speed_wave.frequency = U(0.02, 0.06);
    g.lateral.amplitude = U(0.05, 0.2);
    g.lateral.frequency = U(0.05, 0.1);
    g.vertical.amplitude = U(0.005, 0.015);
    g.vertical.frequency = U(1.0, 2.0);
    g.pitch.amplitude = U(0.005, 0.015);
    g.pitch.frequency = U(0.8, 1.5);
    g.roll.amplitude = U(0.005, 0.015);
    g.roll.frequency = U(0.8, 1.5);
    g.yaw_fast.amplitude = U(0.002, 0.006);
    g.yaw_fast.frequency = U(0.3, 0.6);
    g.height = 1.9;
    g.ramp_s = g.speed / 2.5;
  }
  return m;
}

}  // namespace

MotionProfile DrawMotion(Regime regime, int index, uint64_t seed) {
  if (regime == Regime::kWalking || regime == Regime::kVehicle) {
    return DrawGuidedMotion(regime, index, seed);
  }
  struct Range {
    double amp_lo, amp_hi, f_lo, f_hi;
  };
  Range lin{}, ang{};
  switch (regime) {
    case Regime::kSlow:
      lin = {0.1, 0.5, 0.5, 1.0};
      ang = {0, 0, 0.5, 1.0};
      break;
    case Regime::kMedium:
      lin = {0.5, 1.0, 1.0, 2.0};
      ang = {0.5, 1.0, 2.0, 4.0};
      break;
    case Regime::kFast:
      lin = {1.0, 2.0, 2.0, 4.0};
      ang = {1.0, 2.0, 4.0, 8.0};
      break;
    default:
      break;
  }
  std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(regime), uint32_t(index)};
  std::mt19937_64 rng(seq);
  MotionProfile m;
  for (int j = 0; j < 6; ++j) {
    const Range& r = j < 3 ? lin : ang;
    m.axes[j].amplitude = Uniform(rng, r.amp_lo, r.amp_hi);
    m.axes[j].frequency = Uniform(rng, r.f_lo, r.f_hi);
  }
  return m;
}

std::vector<ImuOutage> ParseImuOutages(const std::string& text) {
  std::vector<ImuOutage> out;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    if (item.empty()) continue;
    ImuOutage o;
    char colon = 0, rest = 0;
    std::istringstream in(item);
    if (!(in >> o.start_s >> colon >> o.length_s) || colon != ':' || (in >> rest) ||
        o.length_s <= 0 || o.start_s < 0) {
      throw std::runtime_error("IMU outage '" + item +
                               "': expected start:length in seconds, length > 0 (e.g. 5.0:0.5)");
    }
    out.push_back(o);
  }
  return out;
}

SimConfig ExperimentConfig(Regime regime, int index, uint64_t seed, WorldKind world) {
  SimConfig c;
  c.world.kind = world;
  c.motion = DrawMotion(regime, index, seed);
  if (world != WorldKind::kBox && !c.motion.guided) {
    std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(regime), uint32_t(index),
                      0x57A7u};
    std::mt19937_64 rng(seq);
    c.motion.guided = true;
    c.motion.guide.start_fraction = Uniform(rng, 0, 1);
    c.motion.guide.speed = regime == Regime::kSlow ? 0.5 : regime == Regime::kMedium ? 1.0 : 1.5;
    c.motion.guide.height = 1.5;
    c.motion.guide.ramp_s = 1.0;
  }
  // A different stream for the noise: {seed, regime, index} mixed by SplitMix64's constant.
  c.seed = seed ^ (0x9E3779B97F4A7C15ULL * (uint64_t(regime) * 1000 + uint64_t(index) + 1));
  return c;
}

}  // namespace ctlio::sim
