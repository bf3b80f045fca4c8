#include "ctlio/sim/lidar_inertial_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "ctlio/sim/normal_draw.h"
#include "ctlio/sim/random_draw.h"

namespace ctlio::sim {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

int64_t PeriodNs(double rate_hz) { return std::llround(1e9 / rate_hz); }

}  // namespace

LidarInertialSim::LidarInertialSim(const SimConfig& config) : config_(config) {
  const auto& L = config_.lidar;
  if (L.beams < 1 || L.firings_per_revolution < 1 || L.rate_hz <= 0 || L.firing_decimation < 1 ||
      config_.imu.rate_hz <= 0 || config_.duration_s <= 0 || config_.integration_step_s <= 0) {
    throw std::runtime_error("LidarInertialSim: invalid configuration (non-positive rate/count)");
  }
  const auto& I = config_.imu;
  if (L.dropout < 0 || L.dropout > 1 || L.max_incidence_deg <= 0 || L.max_incidence_deg > 90 ||
      L.reflect_range < 0 || L.range_noise_per_m < 0 || L.effects.elevation_error_deg < 0 ||
      L.effects.azimuth_error_deg < 0 || L.effects.range_offset_sigma < 0 ||
      L.effects.beam_divergence_rad < 0 || L.effects.mixed_pixel_probability < 0 ||
      L.effects.mixed_pixel_probability > 1 || L.effects.mixed_pixel_min_gap < 0 ||
      !(L.effects.grazing_dropout_start_deg >= 0) || L.effects.grazing_dropout_start_deg > 90 ||
      I.accel_limit < 0 || I.gyro_limit < 0 || I.outage_rate < 0 ||
      (I.outage_rate > 0 &&
       !(I.outage_length_min > 0 && I.outage_length_min <= I.outage_length_max))) {
    throw std::runtime_error(
        "LidarInertialSim: invalid realism option (dropout and mixed-pixel probability in "
        "[0, 1], incidence in (0, 90] deg, grazing-dropout start in [0, 90] deg, "
        "ranges, errors, limits and rates ≥ 0, 0 < outage length min ≤ max)");
  }
  world_ = BuildWorld(config_.world, config_.room);
  const bool guided = config_.motion.guided;
  if (guided && PeakSpeed(config_.motion.guide) > world_.max_speed) {
    std::ostringstream msg;
    msg << "LidarInertialSim: world '" << WorldName(config_.world.kind) << "' allows at most "
        << world_.max_speed << " m/s along its path, the motion asks for "
        << PeakSpeed(config_.motion.guide) << " m/s (the vehicle regime needs box, street or park)";
    throw std::runtime_error(msg.str());
  }
  path_start_ = config_.motion.guide.start_fraction * world_.start_range;
  // Ground-truth pose grid (of P alone when guided).
  const double h = config_.integration_step_s;
  const size_t n = size_t(std::ceil(config_.duration_s / h)) + 2;
  grid_.reserve(n);
  grid_.push_back(guided ? SE3() : config_.world_from_imu0);
  for (size_t i = 1; i < n; ++i) grid_.push_back(MagnusStep(grid_.back(), double(i - 1) * h, h));

  for (const ImuConfig& J : config_.extra_imus) {
    if (!(J.rate_hz > 0) || J.clock_offset_s < 0 || J.accel_noise < 0 || J.gyro_noise < 0 ||
        J.outage_rate < 0) {
      throw std::runtime_error(
          "LidarInertialSim: invalid extra IMU (rate > 0, clock offset, noise, outage rate >= 0)");
    }
  }
  const size_t num_imus = 1 + config_.extra_imus.size();
  imu_.resize(num_imus);
  biases_.resize(num_imus);
  outages_.resize(num_imus);
  for (size_t j = 0; j < num_imus; ++j) GenerateImu(j);
  all_imu_ = num_imus == 1 ? imu_[0] : io::MergeImuStreams(imu_);

  // Beam and azimuth tables; fixed beam-angle errors from their own stream.
  // A unit's errors come from its own seed when given (every sequence of the unit shares them).
  const uint64_t unit_seed = L.unit_seed != 0 ? L.unit_seed : config_.seed;
  if (L.effects.elevation_error_deg > 0 || L.effects.azimuth_error_deg > 0) {
    std::seed_seq beam_seq{uint32_t(unit_seed), uint32_t(unit_seed >> 32), 0xBEA4u};
    std::mt19937_64 beam_rng(beam_seq);
    std::normal_distribution<double> beam_normal;
    for (int b = 0; b < L.beams; ++b) {
      beam_el_error_.push_back(L.effects.elevation_error_deg * M_PI / 180.0 *
                               beam_normal(beam_rng));
      beam_az_error_.push_back(L.effects.azimuth_error_deg * M_PI / 180.0 * beam_normal(beam_rng));
    }
  }
  if (L.effects.range_offset_sigma > 0) {
    std::seed_seq range_seq{uint32_t(unit_seed), uint32_t(unit_seed >> 32), 0x0FF5u};
    std::mt19937_64 range_rng(range_seq);
    std::normal_distribution<double> range_normal;
    for (int b = 0; b < L.beams; ++b) {
      beam_range_offset_.push_back(L.effects.range_offset_sigma * range_normal(range_rng));
    }
  }
  if (!L.elevations_deg.empty() && L.elevations_deg.size() != size_t(L.beams)) {
    throw std::runtime_error("LidarInertialSim: " + std::to_string(L.elevations_deg.size()) +
                             " beam elevations for " + std::to_string(L.beams) + " beams");
  }
  for (int b = 0; b < L.beams; ++b) {
    const double el =
        !L.elevations_deg.empty()
            ? L.elevations_deg[b] * M_PI / 180.0
            : (L.beams == 1 ? L.min_elevation_deg
                            : L.min_elevation_deg +
                                  (L.max_elevation_deg - L.min_elevation_deg) * b / (L.beams - 1)) *
                  M_PI / 180.0;
    cos_el_.push_back(std::cos(el));
    sin_el_.push_back(std::sin(el));
  }
  for (int f = 0; f < L.firings_per_revolution; ++f) {
    const double az = kTwoPi * f / L.firings_per_revolution;
    cos_az_.push_back(std::cos(az));
    sin_az_.push_back(std::sin(az));
  }
  if (!beam_el_error_.empty() && L.pattern.kind == PatternKind::kSpinning) {
    // The same expressions as a ray's direction in Scan had them, so the values are the same.
    for (int b = 0; b < L.beams; ++b) {
      const double el = std::asin(sin_el_[b]) + beam_el_error_[b];
      cos_el_ray_.push_back(std::cos(el));
      sin_el_ray_.push_back(std::sin(el));
    }
    cos_az_ray_.assign(size_t(L.firings_per_revolution) * L.beams, 0.0);
    sin_az_ray_.assign(cos_az_ray_.size(), 0.0);
    for (int f = 0; f < L.firings_per_revolution; f += L.firing_decimation) {
      for (int b = 0; b < L.beams; ++b) {
        const double az = kTwoPi * f / L.firings_per_revolution + beam_az_error_[b];
        cos_az_ray_[size_t(f) * L.beams + b] = std::cos(az);
        sin_az_ray_[size_t(f) * L.beams + b] = std::sin(az);
      }
    }
  }
}

void LidarInertialSim::GenerateImu(size_t j) {
  const ImuConfig& I = ImuConfigOf(j);
  // One generator for noise and bias walk, drawn in sample order; IMU 0 keeps the stream of the
  // single-IMU simulator, IMU j > 0 gets its own.
  std::vector<uint32_t> seeds{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0xC7u};
  if (j > 0) seeds.push_back(uint32_t(j));
  std::seed_seq seq(seeds.begin(), seeds.end());
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal;
  const int64_t dt_ns = PeriodNs(I.rate_hz);
  const double dt = 1e-9 * double(dt_ns);
  const int64_t end_ns = config_.start_ns + std::llround(config_.duration_s * 1e9);
  const bool mounted = !I.body_from_imu.Matrix().isIdentity(0.0);
  std::vector<io::ImuSample>& imu = imu_[j];
  std::vector<Vec6>& biases = biases_[j];
  Vec6 bias;
  bias << I.accel_bias, I.gyro_bias;
  for (int64_t t_ns = config_.start_ns + std::llround(I.clock_offset_s * 1e9); t_ns <= end_ns;
       t_ns += dt_ns) {
    io::ImuSample s = mounted ? TrueImu(Seconds(t_ns), I.body_from_imu) : TrueImu(Seconds(t_ns));
    s.imu = int(j);
    if (I.stamp_offset_s != 0.0) s.t_ns -= std::llround(I.stamp_offset_s * 1e9);
    if (!I.accel_scale.isZero()) s.accel = s.accel.cwiseProduct(Vec3::Ones() + I.accel_scale);
    if (!I.gyro_scale.isZero()) s.gyro = s.gyro.cwiseProduct(Vec3::Ones() + I.gyro_scale);
    for (int k = 0; k < 3; ++k) {
      s.accel[k] += bias[k] + I.accel_noise * normal(rng);
      s.gyro[k] += bias[3 + k] + I.gyro_noise * normal(rng);
    }
    if (I.accel_limit > 0) s.accel = s.accel.cwiseMax(-I.accel_limit).cwiseMin(I.accel_limit);
    if (I.gyro_limit > 0) s.gyro = s.gyro.cwiseMax(-I.gyro_limit).cwiseMin(I.gyro_limit);
    imu.push_back(s);
    biases.push_back(bias);
    for (int k = 0; k < 3; ++k) {
      bias[k] += I.accel_bias_walk * std::sqrt(dt) * normal(rng);
      bias[3 + k] += I.gyro_bias_walk * std::sqrt(dt) * normal(rng);
    }
  }
  ApplyImuOutages(j);
}

Vec6 LidarInertialSim::BodyTwist(double t) const {
  if (!config_.motion.guided) return LocalTwist(t);
  const PoseRates g =
      EvaluateGuide(world_.path, config_.motion.guide, config_.motion.start_s, path_start_, t);
  return LocalPose(t).Inverse().Adjoint() * g.twist + LocalTwist(t);
}

Vec6 LidarInertialSim::BodyTwistRate(double t) const {
  if (!config_.motion.guided) return LocalTwistRate(t);
  const PoseRates g =
      EvaluateGuide(world_.path, config_.motion.guide, config_.motion.start_s, path_start_, t);
  const Mat6 ad_inv = LocalPose(t).Inverse().Adjoint();
  return ad_inv * g.twist_rate - se3::CurlyHat(LocalTwist(t)) * (ad_inv * g.twist) +
         LocalTwistRate(t);
}

Vec6 LidarInertialSim::LocalTwist(double t) const {
  Vec6 xi = Vec6::Zero();
  const double s = t - config_.motion.start_s;
  if (s <= 0) return xi;
  for (int j = 0; j < 6; ++j) {
    const auto& a = config_.motion.axes[j];
    xi[j] = a.amplitude * std::sin(kTwoPi * a.frequency * s);
  }
  return xi;
}

Vec6 LidarInertialSim::LocalTwistRate(double t) const {
  Vec6 d = Vec6::Zero();
  const double s = t - config_.motion.start_s;
  if (s < 0) return d;  // right derivative at start_s
  for (int j = 0; j < 6; ++j) {
    const auto& a = config_.motion.axes[j];
    d[j] = a.amplitude * kTwoPi * a.frequency * std::cos(kTwoPi * a.frequency * s);
  }
  return d;
}

// One step of Ṫ = T·ξ(t)^ with the 4th-order Magnus method (two Gauss points). For a right-
// multiplied equation Ω = h/2(ξ₁ + ξ₂) + (√3 h²/12)[ξ₁, ξ₂], where the se(3) bracket is
// [ξ₁, ξ₂] = curlyhat(ξ₁)·ξ₂ (SPEC §1), and T(t + h) = T(t)·Exp(Ω).
SE3 LidarInertialSim::MagnusStep(const SE3& T, double t, double h) const {
  if (h <= 0) return T;
  const double c = std::sqrt(3.0) / 6.0;
  const Vec6 a1 = LocalTwist(t + (0.5 - c) * h);
  const Vec6 a2 = LocalTwist(t + (0.5 + c) * h);
  const Vec6 omega = 0.5 * h * (a1 + a2) + (std::sqrt(3.0) * h * h / 12.0) * se3::CurlyHat(a1) * a2;
  return T * SE3::Exp(omega);
}

SE3 LidarInertialSim::WorldFromImu(double t) const {
  if (!config_.motion.guided) return LocalPose(t);
  return EvaluateGuide(world_.path, config_.motion.guide, config_.motion.start_s, path_start_, t)
             .pose *
         LocalPose(t);
}

SE3 LidarInertialSim::LocalPose(double t) const {
  const double h = config_.integration_step_s;
  if (t <= 0) return grid_.front();
  size_t k = size_t(std::floor(t / h));
  if (k >= grid_.size() - 1) k = grid_.size() - 2;  // beyond the end: step from the last node
  return MagnusStep(grid_[k], double(k) * h, t - double(k) * h);
}

io::ImuSample LidarInertialSim::TrueImu(double t, const SE3& body_from_imu) const {
  const Vec6 xi = BodyTwist(t);
  const Vec6 dxi = BodyTwistRate(t);
  const Vec3 v = xi.head<3>(), w = xi.tail<3>();
  const Mat3 C_wb = WorldFromImu(t).rotation();
  const Vec3 g_w(0, 0, -config_.imu.gravity);
  io::ImuSample s;
  s.t_ns = config_.start_ns + std::llround(t * 1e9);
  s.gyro = w;
  // Specific force f = C_bw(a_w − g_w) with a_w = C_wb(v̇ + ω×v).
  s.accel = dxi.head<3>() - C_wb.transpose() * g_w;
  if (!config_.imu.body_centric) s.accel += w.cross(v);
  if (!body_from_imu.Matrix().isIdentity(0.0)) {
    // Rigid-body motion of the IMU's origin at lever arm p: ω̇×p + ω×(ω×p), then into the IMU
    // frame (imu_mounting.h).
    const Vec3& p = body_from_imu.translation();
    const Mat3 C_ib = body_from_imu.rotation().transpose();
    s.accel = C_ib * (s.accel + dxi.tail<3>().cross(p) + w.cross(w.cross(p)));
    s.gyro = C_ib * w;
  }
  return s;
}

size_t LidarInertialSim::NumScans() const {
  return size_t(std::floor(config_.duration_s * config_.lidar.rate_hz + 1e-9));
}

int64_t LidarInertialSim::ScanStartNs(size_t k) const {
  return config_.start_ns + int64_t(k) * PeriodNs(config_.lidar.rate_hz);
}

int64_t LidarInertialSim::FiringTimeNs(size_t k, int firing) const {
  // Integer arithmetic: the stored time IS the time the geometry was computed at.
  return ScanStartNs(k) +
         int64_t(firing) * PeriodNs(config_.lidar.rate_hz) / config_.lidar.firings_per_revolution;
}

double LidarInertialSim::CastRay(const Vec3& o, const Vec3& d) const {
  if (config_.world.kind != WorldKind::kBox) return Cast(o, d).t;
  // Inside of the room: the nearest exit through one of the six walls.
  double r = std::numeric_limits<double>::infinity();
  const auto& R = config_.room;
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 0) r = std::min(r, (R.max[i] - o[i]) / d[i]);
    if (d[i] < 0) r = std::min(r, (R.min[i] - o[i]) / d[i]);
  }
  // Obstacles: entry distance (slab test).
  for (const Box& b : R.obstacles) r = std::min(r, IntersectBox(b, o, d, r).t);
  return r;
}

RayHit LidarInertialSim::Cast(const Vec3& o, const Vec3& d, double time) const {
  const auto& L = config_.lidar;
  const bool need_normal = L.max_incidence_deg < 90.0 || L.reflect_range > 0.0 ||
                           L.effects.beam_divergence_rad > 0.0 ||
                           L.effects.grazing_dropout_start_deg < 90.0;
  if (config_.world.kind == WorldKind::kBox && !need_normal) return {CastRay(o, d), Vec3::Zero()};
  // Farther than this no noise draw brings a return back inside max_range.
  const double reach =
      L.max_range * (1 + 6 * L.range_noise_per_m + 35 * L.effects.beam_divergence_rad) +
      6 * L.range_noise + 4 * L.effects.range_offset_sigma + 1.0;
  return world_.scene.Cast(o, d, reach, time);
}

void LidarInertialSim::ApplyImuOutages(size_t j) {
  const ImuConfig& I = ImuConfigOf(j);
  std::vector<ImuOutage>& outages = outages_[j];
  outages = I.outages;
  if (I.outage_rate > 0) {  // Poisson arrivals, uniform lengths, from their own stream
    std::vector<uint32_t> seeds{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0xD0u};
    if (j > 0) seeds.push_back(uint32_t(j));
    std::seed_seq seq(seeds.begin(), seeds.end());
    std::mt19937_64 rng(seq);
    for (double t = 0.0;;) {
      t += -std::log(1.0 - Uniform(rng, 0, 1)) / I.outage_rate;
      if (t >= config_.duration_s) break;
      outages.push_back({t, Uniform(rng, I.outage_length_min, I.outage_length_max)});
    }
  }
  if (outages.empty()) return;
  std::vector<io::ImuSample>& imu = imu_[j];
  std::vector<Vec6>& biases = biases_[j];
  std::vector<io::ImuSample> kept;
  std::vector<Vec6> kept_bias;
  for (size_t i = 0; i < imu.size(); ++i) {
    const int64_t t = imu[i].t_ns - config_.start_ns;
    const bool out = std::any_of(outages.begin(), outages.end(), [t](const ImuOutage& o) {
      const int64_t a = std::llround(o.start_s * 1e9), b = a + std::llround(o.length_s * 1e9);
      return t >= a && t < b;
    });
    if (out) continue;
    kept.push_back(imu[i]);
    kept_bias.push_back(biases[i]);
  }
  imu.swap(kept);
  biases.swap(kept_bias);
}

io::PointCloud LidarInertialSim::Scan(size_t k) const {
  const auto& L = config_.lidar;
  // The ray directions of firing f, beam b at time t [s]: d_l, where the point is reported (the
  // lidar's nominal direction), and d_ray, where the ray really goes (differs by the fixed per-beam
  // angle errors). A spinning lidar's come from its beam table and azimuth; a non-repetitive
  // (Livox) pattern's from scan_pattern.h, without beam errors.
  if (L.pattern.kind != PatternKind::kSpinning) {
    return ScanRays(k, [&](int, int b, double t, Vec3* d_l, Vec3* d_ray) {
      *d_l = *d_ray = PatternDirection(L.pattern, b, L.beams, t);
    });
  }
  const bool beam_errors = !beam_el_error_.empty();
  return ScanRays(k, [&](int f, int b, double, Vec3* d_l, Vec3* d_ray) {
    *d_l = Vec3(cos_el_[b] * cos_az_[f], cos_el_[b] * sin_az_[f], sin_el_[b]);
    *d_ray = *d_l;
    if (beam_errors) {
      const size_t i = size_t(f) * L.beams + b;
      *d_ray =
          Vec3(cos_el_ray_[b] * cos_az_ray_[i], cos_el_ray_[b] * sin_az_ray_[i], sin_el_ray_[b]);
    }
  });
}

template <class Directions>
io::PointCloud LidarInertialSim::ScanRays(size_t k, const Directions& directions) const {
  const auto& L = config_.lidar;
  io::PointCloud cloud;
  cloud.stamp_ns = ScanStartNs(k);
  const size_t firings =
      size_t((L.firings_per_revolution + L.firing_decimation - 1) / L.firing_decimation);
  const size_t capacity = firings * size_t(L.beams);
  cloud.points.reserve(capacity);
  cloud.times_ns.reserve(capacity);
  cloud.ring.reserve(capacity);
  std::seed_seq seq{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0x11DA7u, uint32_t(k)};
  std::mt19937_64 rng(seq);
  NormalDraw normal;  // std::normal_distribution's values, faster
  // Lost returns draw from their own stream, so the noise stream is the same with or without.
  std::seed_seq lost_seq{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0x1057u,
                         uint32_t(k)};
  std::mt19937_64 lost_rng(lost_seq);
  const double cos_max_incidence = std::cos(L.max_incidence_deg * M_PI / 180.0);
  const bool incidence = L.max_incidence_deg < 90.0 || L.reflect_range > 0.0;
  // The unit effects (sensor_effects.h) draw from a third stream, and only when configured, so
  // the other two streams and the output without them are unchanged bit for bit.
  const bool footprint = L.effects.beam_divergence_rad > 0.0,
             grazing = L.effects.grazing_dropout_start_deg < 90.0;
  const bool mixing = L.effects.mixed_pixel_probability > 0.0;
  std::seed_seq effect_seq{uint32_t(config_.seed), uint32_t(config_.seed >> 32), 0xEFFEu,
                           uint32_t(k)};
  std::mt19937_64 effect_rng(effect_seq);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // True range of every beam's ray at the previous kept firing (mixed pixels' neighbours).
  std::vector<double> previous(mixing ? size_t(L.beams) : 0, kInf);
  const double grazing_start = L.effects.grazing_dropout_start_deg * M_PI / 180.0;
  const double grazing_cos_bound = std::cos(grazing_start) + 1e-9;
  // One pose per firing: all beams (lines) of a firing share its time.
  for (int f = 0; f < L.firings_per_revolution; f += L.firing_decimation) {
    const int64_t t_ns = FiringTimeNs(k, f);
    const double t = Seconds(t_ns);
    const SE3 T_wl = WorldFromLidar(t);
    const Vec3& o = T_wl.translation();
    const Mat3& C = T_wl.rotation();
    for (int b = 0; b < L.beams; ++b) {
      Vec3 d_l, d_ray;
      directions(f, b, t, &d_l, &d_ray);
      const double n = normal(rng);  // drawn for every ray: stable streams
      const double noise = L.range_noise * n;
      const bool lost = L.dropout > 0.0 && Uniform(lost_rng, 0, 1) < L.dropout;
      const Vec3 d_w = C * d_ray;
      const RayHit hit = Cast(o, d_w, t);  // t: where the moving people are
      double r = hit.t;
      if (mixing) {
        // The neighbour along the ring (the previous kept firing of this beam): a jump in true
        // range between the two is a depth edge the footprint straddles. (Not the beam below: on
        // the ground far away neighbouring rings are metres apart without any edge.)
        const double r_other = previous[b];
        previous[b] = r;
        if (std::isfinite(r) && std::isfinite(r_other) &&
            std::abs(r_other - r) > L.effects.mixed_pixel_min_gap &&
            Uniform(effect_rng, 0, 1) < L.effects.mixed_pixel_probability) {
          r += Uniform(effect_rng, 0, 1) * (r_other - r);
        }
      }
      if (!std::isfinite(r) || lost) continue;
      double m = L.range_noise_per_m > 0.0 ? r + noise + L.range_noise_per_m * r * n : r + noise;
      if (!beam_range_offset_.empty()) m += beam_range_offset_[b];
      if (footprint || grazing) {
        const double cos_i = std::max(std::abs(hit.normal.dot(d_w)), 1e-9);
        if (footprint) {
          // Uniform depth spread r·δ·tanθ over the footprint (LidarConfig), σ = spread/√12.
          const double tan_i =
              std::min(std::sqrt(std::max(1.0 - cos_i * cos_i, 0.0)) / cos_i, 20.0);
          m += n * r * L.effects.beam_divergence_rad * tan_i / std::sqrt(12.0);
        }
        // acos only near grazing: cos_i above cos(start) by a margin is surely below the start.
        if (grazing && cos_i < grazing_cos_bound) {
          const double theta = std::acos(std::min(cos_i, 1.0));
          if (theta > grazing_start &&
              Uniform(effect_rng, 0, 1) < (theta - grazing_start) / (0.5 * M_PI - grazing_start)) {
            continue;
          }
        }
      }
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
