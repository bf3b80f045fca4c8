#include "ctlio/factors/imu/imu_data.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace ctlio::imu {

void IntegrateInterval(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                       std::int64_t t1_ns, PreintegratedImu* pim, std::int64_t max_gap_ns) {
  if (!(t1_ns > t0_ns)) throw std::runtime_error("IntegrateInterval: empty interval");
  if (samples.empty() || samples.front().t_ns > t0_ns || samples.back().t_ns < t1_ns) {
    throw std::runtime_error("IntegrateInterval: IMU samples do not cover [" +
                             std::to_string(t0_ns) + ", " + std::to_string(t1_ns) + "] ns");
  }
  // Last sample at or before t0.
  auto it = std::upper_bound(samples.begin(), samples.end(), t0_ns,
                             [](std::int64_t t, const ImuSample& s) { return t < s.t_ns; });
  std::size_t k = static_cast<std::size_t>(std::distance(samples.begin(), it)) - 1;
  std::int64_t t = t0_ns;
  while (t < t1_ns) {
    const std::int64_t next = k + 1 < samples.size() ? samples[k + 1].t_ns : t1_ns;
    if (next - samples[k].t_ns > max_gap_ns) {
      throw std::runtime_error("IntegrateInterval: gap of " +
                               std::to_string(next - samples[k].t_ns) + " ns in IMU data at " +
                               std::to_string(samples[k].t_ns));
    }
    const std::int64_t end = std::min(next, t1_ns);
    if (end > t) pim->Integrate(samples[k].accel, samples[k].gyro, 1e-9 * (end - t));
    t = end;
    ++k;
  }
}

}  // namespace ctlio::imu
