#include "ctlio/sim/imu_specs.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ctlio::sim {
namespace {

std::vector<std::string> SplitOn(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

double Number(const std::string& text, const std::string& where) {
  size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v)) {
    throw std::runtime_error(where + ": '" + text + "' is not a number");
  }
  return v;
}

// "a" → (a, a, a) when `scalar_ok`, "x:y:z" → (x, y, z).
Vec3 Triple(const std::string& text, const std::string& where, bool scalar_ok) {
  const auto parts = SplitOn(text, ':');
  if (parts.size() == 1 && scalar_ok) return Vec3::Constant(Number(parts[0], where));
  if (parts.size() != 3) throw std::runtime_error(where + ": expected x:y:z, got '" + text + "'");
  return Vec3(Number(parts[0], where), Number(parts[1], where), Number(parts[2], where));
}

}  // namespace

std::vector<ImuConfig> ParseImuSpecs(const std::string& text, const ImuConfig& first) {
  std::vector<ImuConfig> out;
  for (const std::string& spec : SplitOn(text, ';')) {
    ImuConfig c = first;
    c.outages.clear();
    c.outage_rate = 0.0;
    c.body_from_imu = SE3();
    c.clock_offset_s = 0.0;
    c.stamp_offset_s = 0.0;
    Vec3 xyz = Vec3::Zero(), rpy_deg = Vec3::Zero();
    const std::string imu = "IMU " + std::to_string(out.size() + 1) + " ('" + spec + "')";
    for (const std::string& kv : SplitOn(spec, ',')) {
      const size_t eq = kv.find('=');
      if (eq == std::string::npos)
        throw std::runtime_error(imu + ": '" + kv + "' is not key=value");
      const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
      const std::string where = imu + " " + key;
      if (key == "rate") {
        c.rate_hz = Number(value, where);
        if (!(c.rate_hz > 0)) throw std::runtime_error(where + ": must be > 0");
      } else if (key == "xyz") {
        xyz = Triple(value, where, false);
      } else if (key == "rpy") {
        rpy_deg = Triple(value, where, false);
      } else if (key == "offset") {
        c.clock_offset_s = Number(value, where);
        if (c.clock_offset_s < 0) throw std::runtime_error(where + ": must be >= 0");
      } else if (key == "stamp_offset") {
        c.stamp_offset_s = Number(value, where);
        if (std::abs(c.stamp_offset_s) > 1.0) throw std::runtime_error(where + ": |δ| > 1 s");
      } else if (key == "accel_noise") {
        c.accel_noise = Number(value, where);
      } else if (key == "gyro_noise") {
        c.gyro_noise = Number(value, where);
      } else if (key == "accel_bias") {
        c.accel_bias = Triple(value, where, true);
      } else if (key == "gyro_bias") {
        c.gyro_bias = Triple(value, where, true);
      } else if (key == "outage") {
        for (const std::string& o : SplitOn(value, '+')) {
          const auto parsed = ParseImuOutages(o);
          c.outages.insert(c.outages.end(), parsed.begin(), parsed.end());
        }
      } else {
        throw std::runtime_error(
            where +
            ": unknown key (rate, xyz, rpy, offset, stamp_offset, accel_noise, "
            "gyro_noise, accel_bias, gyro_bias, outage)");
      }
    }
    if (c.accel_noise < 0 || c.gyro_noise < 0) {
      throw std::runtime_error(imu + ": noise must be >= 0");
    }
    const Vec3 r = rpy_deg * M_PI / 180.0;
    const Mat3 C =
        (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
         Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
            .toRotationMatrix();
    c.body_from_imu = SE3(C, xyz);
    out.push_back(c);
  }
  return out;
}

}  // namespace ctlio::sim
