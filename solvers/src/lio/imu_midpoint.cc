#include "ctlio/solvers/lio/imu_midpoint.h"

namespace ctlio::lio {

void InterpolateAtMidpoints(const ImuBuffer& buffer, const std::deque<ImuSample>& samples,
                            std::vector<ImuSegment>* segments) {
  size_t j = 0;  // the first sample after the current midpoint
  for (ImuSegment& seg : *segments) {
    const double t_mid = seg.t_begin + 0.5 * seg.dt;
    while (j < samples.size() && buffer.Seconds(samples[j].t_ns) <= t_mid) ++j;
    if (j == 0 || j == samples.size()) continue;
    const ImuSample& a = samples[j - 1];
    const ImuSample& b = samples[j];
    const double t_a = buffer.Seconds(a.t_ns);
    const double s = (t_mid - t_a) / (buffer.Seconds(b.t_ns) - t_a);
    seg.gyro = a.gyro + s * (b.gyro - a.gyro);
    seg.accel = a.accel + s * (b.accel - a.accel);
  }
}

}  // namespace ctlio::lio
