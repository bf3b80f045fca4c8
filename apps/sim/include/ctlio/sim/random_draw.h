// Portable random draws shared by the simulator and its worlds.
#pragma once

#include <random>

namespace ctlio::sim {

// Uniform in [lo, hi) from the top 53 bits (portable, unlike std::uniform_real_distribution).
inline double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * double(rng() >> 11) * 0x1.0p-53;
}

}  // namespace ctlio::sim
