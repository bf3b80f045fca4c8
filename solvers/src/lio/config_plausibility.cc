#include "ctlio/solvers/lio/config_plausibility.h"

#include <cmath>
#include <sstream>

namespace ctlio::lio {
namespace {

// "<key> = <value> <unit>: <what> above <bound> <unit> ...; <effect>".
void Check(const char* key, double value, double bound, const char* unit, const char* what,
           const char* effect, std::vector<std::string>* out) {
  if (!(value > bound)) return;
  std::ostringstream m;
  m.precision(4);
  m << key << " = " << value << ' ' << unit << ": " << what << " above " << bound << ' ' << unit
    << " is beyond any real IMU; " << effect;
  out->push_back(m.str());
}

}  // namespace

std::vector<std::string> ImplausibleSettings(const OdometryConfig& c) {
  std::vector<std::string> out;
  if (c.method == LioMethod::kLidarOnly) return out;
  const bool gp = c.method != LioMethod::kImuInput;
  // Bias walks as σ per √s: sqrt(variance per period / period).
  const double period = c.bias_walk_period > 0 ? c.bias_walk_period : 1.0;
  const double accel_walk = std::sqrt(std::max(0.0, c.bias_accel_walk) / period);
  const double gyro_walk = std::sqrt(std::max(0.0, c.bias_gyro_walk) / period);
  if (gp) {
    if (c.method == LioMethod::kSingerLio) {
      Check("imu.accel_variance", c.accel_variance, 100.0, "(m/s^2)^2",
            "an accelerometer variance (sigma 10 m/s^2)",
            "the accelerometer then weighs nothing in the estimate", &out);
      Check("imu.accel_loss_scale", c.accel_loss_scale, 1e3, "", "a Cauchy scale",
            "it is no robust loss at all (0 says that)", &out);
      for (size_t j = 0; j < c.imus.size(); ++j) {
        Check(("imus[" + std::to_string(j) + "].accel_variance").c_str(), c.imus[j].accel_variance,
              100.0, "(m/s^2)^2", "an accelerometer variance (sigma 10 m/s^2)",
              "this accelerometer then weighs nothing in the estimate", &out);
      }
    }
    Check("imu.gyro_variance", c.gyro_variance, 1.0, "(rad/s)^2", "a gyro variance (sigma 1 rad/s)",
          "the gyro then weighs nothing in the estimate", &out);
  } else {
    Check("imu.input_accel_sigma", c.input_accel_sigma, 10.0, "m/s^2", "an accelerometer sigma",
          "the preintegrated accelerometer then weighs nothing", &out);
    Check("imu.input_gyro_sigma", c.input_gyro_sigma, 1.0, "rad/s", "a gyro sigma",
          "the preintegrated gyro then weighs nothing", &out);
  }
  if (c.method != LioMethod::kLidarGyro) {
    Check("imu.bias_accel_walk (per sqrt(s), from bias_walk_period)", accel_walk, 1.0,
          "m/s^2/sqrt(s)", "an accelerometer bias random walk",
          "the bias then absorbs the platform's acceleration", &out);
  }
  Check("imu.bias_gyro_walk (per sqrt(s), from bias_walk_period)", gyro_walk, 0.1, "rad/s/sqrt(s)",
        "a gyro bias random walk", "the bias then absorbs the rotation rate", &out);
  Check("imu.bias_walk_period", c.bias_walk_period, 3600.0, "s",
        "a bias walk period (the walks are per this period)",
        "the biases are then practically constant", &out);
  return out;
}

}  // namespace ctlio::lio
