#include "ctlio/io/point_time_check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace ctlio::io {
namespace {

constexpr int64_t kFar = 1'000'000'000'000'000'000;

// The q-quantile of `v` (partially reordered).
double Quantile(std::vector<double>* v, double q) {
  const size_t k = std::min(v->size() - 1, size_t(q * double(v->size() - 1) + 0.5));
  std::nth_element(v->begin(), v->begin() + k, v->end());
  return (*v)[k];
}

std::string Seconds(double ns) {
  std::ostringstream s;
  s.precision(6);
  s << 1e-9 * ns << " s";
  return s.str();
}

// Whether the points, taken in time order, follow a scan pattern: a spinning lidar's azimuth (or
// a Livox rosette's) moves on by little between consecutive firings, whereas times that are ring
// numbers or ranges order the points arbitrarily (median azimuth step near π/2). Only steps
// between different times count: the beams of one firing share a time and an azimuth, so with
// them in, a many-beam cloud whose times were scrambled (a 16-bit field wrapping every 65.5 µs)
// still had a median step of 0 and was rescaled as if it were a sweep in µs.
bool FollowsScanPattern(const PointCloud& c) {
  std::vector<size_t> order(c.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return c.times_ns[a] < c.times_ns[b]; });
  std::vector<double> steps;
  steps.reserve(order.size());
  for (size_t k = 1; k < order.size(); ++k) {
    if (c.times_ns[order[k]] == c.times_ns[order[k - 1]]) continue;
    const Vec3& p = c.points[order[k - 1]];
    const Vec3& q = c.points[order[k]];
    const double d = std::atan2(q.y(), q.x()) - std::atan2(p.y(), p.x());
    steps.push_back(std::abs(std::remainder(d, 2 * M_PI)));
  }
  return !steps.empty() && Quantile(&steps, 0.5) < 0.3;
}

}  // namespace

PointTimeCheck CheckPointTimes(PointCloud* cloud, int64_t period_ns) {
  PointTimeCheck r;
  const size_t n = cloud->times_ns.size();
  if (n < 2 || n != cloud->size() || period_ns <= 0) return r;
  const int64_t stamp = cloud->stamp_ns;
  const auto [lo, hi] = std::minmax_element(cloud->times_ns.begin(), cloud->times_ns.end());
  const double period = double(period_ns);
  if (*lo == *hi) {
    r.verdict = PointTimeCheck::kNotASweep;
    r.reason = *lo == stamp ? "all " + std::to_string(n) + " points at the scan stamp"
                            : "all " + std::to_string(n) + " points at one instant, " +
                                  Seconds(double(*lo) - double(stamp)) + " from the scan stamp";
    return r;
  }
  if (n < kMinPointsForSpread) return r;
  std::vector<double> offsets(n);
  for (size_t i = 0; i < n; ++i) offsets[i] = double(cloud->times_ns[i]) - double(stamp);
  const double median = Quantile(&offsets, 0.5);
  const double spread = Quantile(&offsets, 0.95) - Quantile(&offsets, 0.05);
  auto near_stamp = [&](double m) { return std::abs(m) <= 2 * period; };
  if (spread >= period / 100 && spread <= 1.5 * period && near_stamp(median)) return r;

  std::ostringstream what;
  what << "per-point times span " << Seconds(spread) << " (5-95 % quantiles), median "
       << Seconds(median) << " from the scan stamp: not a sweep of " << Seconds(period);
  for (double f : {1e3, 1e6, 1e-3, 1e-6}) {
    const double s = spread * f, m = median * f;
    if (s < 0.2 * period || s > 1.5 * period || !near_stamp(m)) continue;
    // Factors are 10³ apart and the window is narrower, so at most one fits; it must also order
    // the points as a sweep would, or the field holds something else (ring, range).
    if (!FollowsScanPattern(*cloud)) {
      what << "; a unit factor " << f << " would make them span " << Seconds(s)
           << ", but in time order the points do not follow a scan (a ring, range or other "
              "field read as time?)";
      break;
    }
    for (int64_t& t : cloud->times_ns) {
      // A point far outside the sweep may leave the int64 range once scaled: it is parked 10⁹ s
      // away, where DropPointsOutside removes it like any other point outside the sweep.
      const double v = (double(t) - double(stamp)) * f;
      t = stamp + (std::abs(v) < 1e18 ? int64_t(std::llround(v)) : (v > 0 ? 1 : -1) * kFar);
    }
    r.verdict = PointTimeCheck::kRescaled;
    r.factor = f;
    what << "; read with a unit factor " << f << " (span now " << Seconds(s) << "; "
         << (f == 1e3    ? "microseconds where nanoseconds are expected?"
             : f == 1e6  ? "milliseconds where nanoseconds are expected?"
             : f == 1e-3 ? "milliseconds where seconds are expected?"
                         : "microseconds where seconds are expected?")
         << ")";
    r.reason = what.str();
    return r;
  }
  if (spread < period / 100 && spread * 1e3 < 0.2 * period) {
    what << "; no unit factor makes it one (an 8/16-bit field, a ring number?)";
  }
  r.verdict = PointTimeCheck::kNotASweep;
  r.reason = what.str();
  return r;
}

}  // namespace ctlio::io
