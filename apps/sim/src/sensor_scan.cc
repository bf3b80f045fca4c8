// Scans of the non-repetitive (Livox) patterns: the rays of LidarInertialSim::Scan with the
// directions of scan_pattern.h. One pose per firing (all lines of a firing share its time), the
// noise drawn per ray from the same per-scan stream as the spinning lidar's.
#include <cmath>
#include <random>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/sim/random_draw.h"

namespace ctlio::sim {

io::PointCloud LidarInertialSim::PatternScan(size_t k) const {
  const auto& L = config_.lidar;
  io::PointCloud cloud;
  cloud.stamp_ns = ScanStartNs(k);
  const size_t capacity =
      size_t((L.firings_per_revolution + L.firing_decimation - 1) / L.firing_decimation) *
      size_t(L.beams);
  cloud.points.reserve(capacity);
  cloud.times_ns.reserve(capacity);
  cloud.ring.reserve(capacity);
  std::seed_seq seq{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0x11DA7u, uint32_t(k)};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal;
  std::seed_seq lost_seq{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0x1057u,
                         uint32_t(k)};
  std::mt19937_64 lost_rng(lost_seq);
  const double cos_max_incidence = std::cos(L.max_incidence_deg * M_PI / 180.0);
  const bool incidence = L.max_incidence_deg < 90.0 || L.reflect_range > 0.0;
  for (int f = 0; f < L.firings_per_revolution; f += L.firing_decimation) {
    const int64_t t_ns = FiringTimeNs(k, f);
    const double t = Seconds(t_ns);
    const SE3 T_wl = WorldFromLidar(t);
    const Vec3& o = T_wl.translation();
    const Mat3& C = T_wl.rotation();
    for (int b = 0; b < L.beams; ++b) {
      const Vec3 d_l = PatternDirection(L.pattern, b, L.beams, t);
      const double n = normal(rng);
      const bool lost = L.dropout > 0.0 && Uniform(lost_rng, 0, 1) < L.dropout;
      const Vec3 d_w = C * d_l;
      const RayHit hit = Cast(o, d_w, t);  // t: where the moving people are
      const double r = hit.t;
      if (!std::isfinite(r) || lost) continue;
      const double m = r + L.range_noise * n + L.range_noise_per_m * r * n;
      if (m < L.min_range || m > L.max_range) continue;
      if (incidence) {
        const double cos_incidence = std::abs(hit.normal.dot(d_w));
        if (cos_incidence < cos_max_incidence) continue;
        if (L.reflect_range > 0.0 && r > L.reflect_range * std::sqrt(cos_incidence)) continue;
      }
      cloud.points.push_back(m * d_l);
      cloud.times_ns.push_back(t_ns);
      cloud.ring.push_back(uint16_t(b));
    }
  }
  return cloud;
}

}  // namespace ctlio::sim
