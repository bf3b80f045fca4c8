// Interval arithmetic on int64 nanosecond times that cannot overflow. Every reader and the
// odometry widen a stamp by a period or a tolerance (a tolerance window [stamp − d, end + d], a
// nominal interval [stamp, stamp + period − 1]); near the int64 limits (±9.2e18 ns, ±292 years)
// plain + and − wrap around, and a wrapped window is inverted (lo > hi): every point of the scan
// fell outside it and the whole scan was dropped, or an inverted interval was printed. Here, next
// to ImuSample's t_ns, so that apps/io and solvers/lio share one definition.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace ctlio {

// a + b clamped to the int64 range: for the bounds of a window, where a bound past the limits
// means "no bound on that side" (every representable time is inside).
inline int64_t SaturatingAddNs(int64_t a, int64_t b) {
  int64_t r = 0;
  if (!__builtin_add_overflow(a, b, &r)) return r;
  return b > 0 ? std::numeric_limits<int64_t>::max() : std::numeric_limits<int64_t>::min();
}

// a − b clamped to the int64 range.
inline int64_t SaturatingSubNs(int64_t a, int64_t b) {
  int64_t r = 0;
  if (!__builtin_sub_overflow(a, b, &r)) return r;
  return b < 0 ? std::numeric_limits<int64_t>::max() : std::numeric_limits<int64_t>::min();
}

// a + b, or an error `<where>: time a ns + b ns is outside the int64 nanosecond range …` for a
// time that must exist (the end of a nominal interval): no clamped value would be the right one.
inline int64_t CheckedAddNs(int64_t a, int64_t b, const std::string& where) {
  int64_t r = 0;
  if (__builtin_add_overflow(a, b, &r)) {
    throw std::runtime_error(where + ": time " + std::to_string(a) + " ns + " + std::to_string(b) +
                             " ns is outside the int64 nanosecond range (±9.22e18 ns, ±292 "
                             "years): a stamp within a scan period of the limit");
  }
  return r;
}

}  // namespace ctlio
