#include "ctlio/solvers/lio/imu_midpoint.h"

#include <algorithm>

namespace ctlio::lio {

void InterpolateAtMidpoints(const ImuBuffer& buffer, const std::deque<ImuSample>& samples,
                            std::vector<ImuSegment>* segments) {
  size_t j = 0;  // the first sample after the current midpoint
  for (ImuSegment& seg : *segments) {
    const double t_mid = seg.t_begin + 0.5 * seg.dt;
    while (j < samples.size() && buffer.Seconds(samples[j].t_ns) <= t_mid) ++j;
    if (j == 0) continue;
    size_t i_b = j;
    if (j == samples.size()) {
      // The newest stretch: its next sample has not arrived. Held, the stretch of length δ would
      // be off by ω̇·δ/2 in rate (ω̇·δ²/2 in angle, once per scan: at 200 Hz in fast motion 10×
      // the rotation σ, falling as Δt²); the line through the last two samples carries it to
      // O(ω̈·δ·Δt), if the stretch ends within one sample period of the newest sample.
      if (j < 2) continue;
      const double t_last = buffer.Seconds(samples[j - 1].t_ns);
      const double period = t_last - buffer.Seconds(samples[j - 2].t_ns);
      if (!(period > 0.0) || seg.t_begin + seg.dt > t_last + period + 1e-9) continue;
      i_b = j - 1;
    }
    const ImuSample& a = samples[i_b - 1];
    const ImuSample& b = samples[i_b];
    const double t_a = buffer.Seconds(a.t_ns);
    const double s = (t_mid - t_a) / (buffer.Seconds(b.t_ns) - t_a);
    seg.gyro = a.gyro + s * (b.gyro - a.gyro);
    seg.accel = a.accel + s * (b.accel - a.accel);
  }
}

void SplitSegments(int parts, std::vector<ImuSegment>* segments) {
  if (parts <= 1) return;
  std::vector<ImuSegment> split;
  split.reserve(segments->size() * static_cast<size_t>(parts));
  for (const ImuSegment& seg : *segments) {
    const double dt = seg.dt / parts;
    for (int k = 0; k < parts; ++k) {
      ImuSegment part = seg;
      part.t_begin = seg.t_begin + k * dt;
      part.dt = dt;
      split.push_back(part);
    }
  }
  segments->swap(split);
}

void InterpolateCubicAtMidpoints(const ImuBuffer& buffer, const std::deque<ImuSample>& samples,
                                 std::vector<ImuSegment>* segments) {
  InterpolateAtMidpoints(buffer, samples, segments);
  size_t j = 0;  // the first sample after the current midpoint
  for (ImuSegment& seg : *segments) {
    const double t_mid = seg.t_begin + 0.5 * seg.dt;
    while (j < samples.size() && buffer.Seconds(samples[j].t_ns) <= t_mid) ++j;
    if (j < 2 || j + 1 >= samples.size()) continue;  // fewer than two on a side: the line
    // Lagrange's cubic through samples j − 2 … j + 1 at t_mid.
    double t[4];
    for (int k = 0; k < 4; ++k) t[k] = buffer.Seconds(samples[j - 2 + k].t_ns);
    // Across a hole (a lost sample or an outage) the cubic would swing between its points: the
    // line then, as InterpolateAtMidpoints has it.
    const double shortest = std::min({t[1] - t[0], t[2] - t[1], t[3] - t[2]});
    const double longest = std::max({t[1] - t[0], t[2] - t[1], t[3] - t[2]});
    if (!(longest <= 1.5 * shortest)) continue;
    Vec3 gyro = Vec3::Zero(), accel = Vec3::Zero();
    for (int k = 0; k < 4; ++k) {
      double weight = 1.0;
      for (int m = 0; m < 4; ++m) {
        if (m != k) weight *= (t_mid - t[m]) / (t[k] - t[m]);
      }
      gyro += weight * samples[j - 2 + k].gyro;
      accel += weight * samples[j - 2 + k].accel;
    }
    seg.gyro = gyro;
    seg.accel = accel;
  }
}

}  // namespace ctlio::lio
