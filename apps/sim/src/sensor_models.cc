#include "ctlio/sim/sensor_models.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ctlio/io/newer_college.h"

namespace ctlio::sim {
namespace {

// Per-sample σ of a noise density [unit/√Hz] sampled at `rate_hz`.
double PerSample(double density, double rate_hz) { return density * std::sqrt(rate_hz); }

constexpr double kDeg = M_PI / 180.0;
constexpr double kG = 9.80665;
constexpr double kGoldenRatio = 1.6180339887498949;

// An Ouster sensor through ouster_ros: uniform beams, 1024 columns at 10 Hz, the internal IMU at
// 100 Hz with the Newer College preset's noise (presets.h), and ouster_ros's default
// T_imu_lidar (imu_to_sensor and lidar_to_sensor of the sensor's metadata: rotation
// diag(−1, −1, 1), translation (−6.253, 11.775, 28.535) mm; the same on OS0 and OS1).
SensorModel Ouster(const std::string& name, const std::string& description, int beams,
                   double half_fov_deg, double min_range, double max_range) {
  SensorModel m;
  m.name = name;
  m.description = description;
  LidarConfig& L = m.lidar;
  L.beams = beams;
  L.min_elevation_deg = -half_fov_deg;
  L.max_elevation_deg = half_fov_deg;
  L.firings_per_revolution = 1024;
  L.rate_hz = 10.0;
  L.range_noise = 0.015;  // ±1.5 cm repeatability at high SNR, growing with range
  L.range_noise_per_m = 0.0005;
  L.min_range = min_range;
  L.max_range = max_range;
  m.imu_rate_hz = 100.0;
  m.accel_noise = 0.05;
  m.gyro_noise = 0.005;
  m.accel_bias_walk = 1e-3;
  m.gyro_bias_walk = 1e-4;
  m.imu_from_lidar = io::NewerCollegeImuFromLidar();
  m.driver = io::DriverConventionOf(io::PointFormat::kOuster);
  m.effects_family = "ouster";
  return m;
}

// A lidar with an external tactical-grade MEMS IMU (gyro 0.01 °/s/√Hz, accel 60 µg/√Hz, bias
// instability class 1e-4 m/s²/√s, 1e-5 rad/s/√s) mounted `below` m under the lidar, axes aligned.
void ExternalImu(SensorModel* m, double rate_hz, double below) {
  m->imu_rate_hz = rate_hz;
  m->accel_noise = PerSample(60e-6 * kG, rate_hz);
  m->gyro_noise = PerSample(0.01 * kDeg, rate_hz);
  m->accel_bias_walk = 1e-4;
  m->gyro_bias_walk = 1e-5;
  m->imu_from_lidar = SE3(Mat3::Identity(), Vec3(0.0, 0.0, below));
}

// Livox's built-in IMU (BMI088 class: gyro 0.014 °/s/√Hz, accel 175 µg/√Hz) at 200 Hz.
void LivoxImu(SensorModel* m, const Vec3& lidar_in_imu) {
  m->imu_rate_hz = 200.0;
  m->accel_noise = PerSample(175e-6 * kG, 200.0);
  m->gyro_noise = PerSample(0.014 * kDeg, 200.0);
  m->accel_bias_walk = 1e-3;
  m->gyro_bias_walk = 1e-4;
  m->imu_from_lidar = SE3(Mat3::Identity(), lidar_in_imu);
  m->driver = io::DriverConventionOf(io::PointFormat::kLivoxCustomMsg);
  m->effects_family = "livox";
}

std::vector<SensorModel> BuildModels() {
  std::vector<SensorModel> models;
  models.push_back(Ouster("os0_128", "Ouster OS0-128: 128 beams over ±45°, 1024 × 10 Hz, 0.3–50 m",
                          128, 45.0, 0.3, 50.0));
  models.push_back(Ouster("os1_64",
                          "Ouster OS1-64: 64 beams over ±16.6°, 1024 × 10 Hz, 0.8–120 m (the "
                          "Newer College sensor)",
                          64, 16.6, 0.8, 120.0));
  models.push_back(Ouster("os1_128",
                          "Ouster OS1-128: 128 beams over ±22.5°, 1024 × 10 Hz, 0.3–120 m", 128,
                          22.5, 0.3, 120.0));
  {
    // Velodyne VLP-16 (user manual: lasers at −15…+15° every 2°, 0.2° at 10 Hz, 100 m, ±3 cm).
    SensorModel m;
    m.name = "vlp16";
    m.description =
        "Velodyne VLP-16: 16 beams −15…+15° every 2°, 1800 × 10 Hz, 0.5–100 m, "
        "external IMU 200 Hz";
    LidarConfig& L = m.lidar;
    L.beams = 16;
    for (int b = 0; b < 16; ++b) L.elevations_deg.push_back(-15.0 + 2.0 * b);
    L.min_elevation_deg = -15.0;
    L.max_elevation_deg = 15.0;
    L.firings_per_revolution = 1800;
    L.range_noise = 0.015;
    L.min_range = 0.5;
    L.max_range = 100.0;
    ExternalImu(&m, 200.0, 0.10);
    m.driver = io::DriverConventionOf(io::PointFormat::kVelodyne);
    m.effects_family = "velodyne";
    models.push_back(m);
  }
  {
    // Velodyne HDL-32E (manual: +10.67…−30.67° in 1.33° steps, i.e. k·4/3° for k = −23…8 as the
    // manual rounds them; 46.08 µs firing cycle: 2170 firings per 10 Hz revolution; 1–100 m,
    // ±2 cm).
    SensorModel m;
    m.name = "hdl32e";
    m.description =
        "Velodyne HDL-32E: 32 beams −30.67…+10.67° in 1.33° steps, 2170 × 10 Hz, "
        "1–100 m, external IMU 400 Hz";
    LidarConfig& L = m.lidar;
    L.beams = 32;
    for (int k = -23; k <= 8; ++k) L.elevations_deg.push_back(std::round(k * 400.0 / 3.0) / 100.0);
    L.min_elevation_deg = -30.67;
    L.max_elevation_deg = 10.67;
    L.firings_per_revolution = 2170;
    L.range_noise = 0.01;
    L.min_range = 1.0;
    L.max_range = 100.0;
    ExternalImu(&m, 400.0, 0.15);
    m.driver = io::DriverConventionOf(io::PointFormat::kVelodyne);
    m.effects_family = "velodyne";
    models.push_back(m);
  }
  {
    // Hesai Pandar XT-32 (datasheet: −16…+15° every 1°, 0.18° at 10 Hz, 0.05–120 m, ±1 cm).
    SensorModel m;
    m.name = "pandar_xt32";
    m.description =
        "Hesai Pandar XT-32: 32 beams −16…+15° every 1°, 2000 × 10 Hz, 0.05–120 m, "
        "external IMU 200 Hz";
    LidarConfig& L = m.lidar;
    L.beams = 32;
    for (int b = 0; b < 32; ++b) L.elevations_deg.push_back(-16.0 + b);
    L.min_elevation_deg = -16.0;
    L.max_elevation_deg = 15.0;
    L.firings_per_revolution = 2000;
    L.range_noise = 0.01;
    L.min_range = 0.05;
    L.max_range = 120.0;
    ExternalImu(&m, 200.0, 0.10);
    m.driver = io::DriverConventionOf(io::PointFormat::kHesai);
    m.effects_family = "hesai";
    models.push_back(m);
  }
  {
    // Livox Mid-360 (datasheet: 360° × −7…52°, 200 000 points/s, 10 Hz frames, 0.1–40 m at 10 %
    // reflectivity, ≤ 2 cm at 10 m; 4 lines). Extrinsic: the lidar at (−0.011, −0.02329,
    // 0.04412) m in the IMU frame, axes aligned (Livox's published offset, as FAST-LIO's
    // mid360.yaml uses it).
    SensorModel m;
    m.name = "mid360";
    m.description =
        "Livox Mid-360: non-repetitive 360° × −7…52°, 4 lines, 200 k points/s, 10 Hz, "
        "0.1–40 m, built-in IMU 200 Hz (g)";
    LidarConfig& L = m.lidar;
    L.beams = 4;
    L.firings_per_revolution = 5000;  // 200 000 / 4 lines / 10 Hz
    L.min_elevation_deg = -7.0;
    L.max_elevation_deg = 52.0;
    L.range_noise = 0.02;
    L.min_range = 0.1;
    L.max_range = 40.0;
    ScanPattern& p = L.pattern;
    p.kind = PatternKind::kMid360;
    p.azimuth_hz = 10.0 * kGoldenRatio;
    p.f1_hz = 1000.0 * kGoldenRatio;
    p.f2_hz = 1000.0 * std::sqrt(2.0);
    p.weight = 0.7;
    p.min_elevation_deg = -7.0;
    p.max_elevation_deg = 52.0;
    LivoxImu(&m, Vec3(-0.011, -0.02329, 0.04412));
    models.push_back(m);
  }
  {
    // Livox Avia (datasheet: 70.4° × 77.2° non-repetitive rosette, 240 000 points/s (first
    // return), 6 lines, 190 m at 10 %, 2 cm). Extrinsic: the lidar at (0.04165, 0.02326,
    // −0.0284) m in the IMU frame (FAST-LIO's avia.yaml).
    SensorModel m;
    m.name = "avia";
    m.description =
        "Livox Avia: non-repetitive rosette 70.4° × 77.2° forward, 6 lines, 240 k "
        "points/s, 10 Hz, 1–190 m, built-in IMU 200 Hz (g)";
    LidarConfig& L = m.lidar;
    L.beams = 6;
    L.firings_per_revolution = 4000;  // 240 000 / 6 lines / 10 Hz
    L.min_elevation_deg = -38.6;
    L.max_elevation_deg = 38.6;
    L.range_noise = 0.02;
    L.min_range = 1.0;
    L.max_range = 190.0;
    ScanPattern& p = L.pattern;
    p.kind = PatternKind::kRosette;
    p.f1_hz = 97.1;
    p.f2_hz = -97.1 * kGoldenRatio;
    p.half_azimuth_deg = 35.2;
    p.half_elevation_deg = 38.6;
    LivoxImu(&m, Vec3(0.04165, 0.02326, -0.0284));
    models.push_back(m);
  }
  return models;
}

}  // namespace

const std::vector<SensorModel>& SensorModels() {
  static const std::vector<SensorModel> models = BuildModels();
  return models;
}

const SensorModel& FindSensorModel(const std::string& name) {
  for (const SensorModel& m : SensorModels()) {
    if (m.name == name) return m;
  }
  std::string names;
  for (const SensorModel& m : SensorModels()) names += (names.empty() ? "" : ", ") + m.name;
  throw std::runtime_error("unknown sensor '" + name + "' (" + names + ")");
}

std::string ListSensorModels() {
  std::ostringstream s;
  for (const SensorModel& m : SensorModels()) {
    s << m.name << std::string(m.name.size() < 13 ? 13 - m.name.size() : 1, ' ') << m.description
      << "\n";
  }
  return s.str();
}

void ApplySensorModel(const SensorModel& model, SimConfig* config) {
  config->lidar = model.lidar;
  ImuConfig& I = config->imu;
  I.rate_hz = model.imu_rate_hz;
  I.accel_noise = model.accel_noise;
  I.gyro_noise = model.gyro_noise;
  I.accel_bias_walk = model.accel_bias_walk;
  I.gyro_bias_walk = model.gyro_bias_walk;
  I.body_centric = false;  // a real accelerometer measures the exact specific force
  config->imu_from_lidar = model.imu_from_lidar;
}

}  // namespace ctlio::sim
