// std::normal_distribution<double> over std::mt19937_64 as libstdc++ computes it (Marsaglia's
// polar method, the second value of a pair kept for the next draw), without the long-double
// logarithm its generate_canonical evaluates at every uniform draw (log(2^64)/log(2), a constant)
// — a third of a sweep's simulation time. The values are the same bit for bit (test
// sim.NormalDraw), so every simulated scan is unchanged; with another standard library it is
// std::normal_distribution itself.
#pragma once

#include <cmath>
#include <random>

namespace ctlio::sim {

class NormalDraw {
 public:
  double operator()(std::mt19937_64& rng) {
#if defined(__GLIBCXX__)
    double value;
    if (saved_available_) {
      saved_available_ = false;
      value = saved_;
    } else {
      double x, y, r2;
      do {
        x = 2.0 * Canonical(rng) - 1.0;
        y = 2.0 * Canonical(rng) - 1.0;
        r2 = x * x + y * y;
      } while (r2 > 1.0 || r2 == 0.0);
      const double mult = std::sqrt(-2 * std::log(r2) / r2);
      saved_ = x * mult;
      saved_available_ = true;
      value = y * mult;
    }
    return value * 1.0 + 0.0;  // σ = 1, mean 0, as the distribution applies them
#else
    return normal_(rng);
#endif
  }

 private:
#if defined(__GLIBCXX__)
  // generate_canonical<double, 53> of a 64-bit engine: one draw divided by 2^64 (exact), kept
  // below 1.
  static double Canonical(std::mt19937_64& rng) {
    const double u = double(rng()) / 18446744073709551616.0;
    return u >= 1.0 ? std::nextafter(1.0, 0.0) : u;
  }
  double saved_ = 0.0;
  bool saved_available_ = false;
#else
  std::normal_distribution<double> normal_;
#endif
};

}  // namespace ctlio::sim
