// NormalDraw (normal_draw.h) gives std::normal_distribution's values bit for bit, so the
// simulator's scans did not change when it replaced the distribution.
#include "ctlio/sim/normal_draw.h"

#include <gtest/gtest.h>

#include <cstring>

namespace ctlio::sim {
namespace {

TEST(NormalDraw, SameValuesAsTheStandardDistribution) {
  for (const uint64_t seed : {1ULL, 2403059680ULL}) {
    std::mt19937_64 a(seed), b(seed);
    std::normal_distribution<double> reference;
    NormalDraw draw;
    double sum = 0.0, sq = 0.0;
    for (int i = 0; i < 1000000; ++i) {
      const double x = reference(a), y = draw(b);
      ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << "draw " << i << ": " << x << " vs " << y;
      sum += y;
      sq += y * y;
    }
    EXPECT_NEAR(sum / 1e6, 0.0, 0.005);
    EXPECT_NEAR(sq / 1e6, 1.0, 0.005);
    EXPECT_EQ(a(), b());  // the engines advanced alike
  }
}

}  // namespace
}  // namespace ctlio::sim
