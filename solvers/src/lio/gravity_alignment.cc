#include "ctlio/solvers/lio/gravity_alignment.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <vector>

#include "ctlio/factors/imu/gravity_initialization.h"
#include "ctlio/solvers/lio/input_checks.h"

namespace ctlio::lio {

bool InitialiseGravity(const ImuBuffer& imu, double t_end, const OdometryConfig& config, Mat3* C_mi,
                       std::string* message) {
  const bool uses_accel =
      config.method == LioMethod::kSingerLio || config.method == LioMethod::kImuInput;
  // From the input IMU (the first unless imu.input_imu names another), at rest: its lever arm
  // does not matter, its rotation turns its gravity direction into the robot frame's.
  const std::deque<ImuSample>& stream = imu.samples(config.input_imu);
  const std::vector<ImuSample> samples(stream.begin(), stream.end());
  if (samples.empty()) {
    *message = "gravity initialisation: no IMU samples before the first scan end";
    return false;
  }
  const int64_t end_ns = imu.origin_ns() + static_cast<int64_t>(std::llround(t_end * 1e9));
  const int64_t t0_ns =
      std::max(samples.front().t_ns,
               end_ns - static_cast<int64_t>(std::llround(config.gravity_init_duration * 1e9)));
  // Input gate (input_checks.h): an accelerometer in g, or columns swapped, shows as a mean
  // specific force far from the configured gravity. Named as such before the stillness tests of
  // imu::InitializeGravity, whose 0.3 m/s² limit would report it as mere motion or bias.
  if (uses_accel) {
    std::vector<ImuSample> window;
    for (const ImuSample& s : samples) {
      if (s.t_ns >= t0_ns && s.t_ns <= end_ns) window.push_back(s);
    }
    if (const auto m =
            CheckGravityMagnitude(window, config.gravity, config.input.gravity_tolerance)) {
      *message = "gravity initialisation: " + *m;
      return false;
    }
  }
  imu::GravityInitializationOptions options;
  options.gravity = config.gravity;
  options.max_block_accel_deviation = config.gravity_init_max_std;
  options.min_samples = 10;
  try {
    *C_mi = imu::InitializeGravity(samples, t0_ns, end_ns - t0_ns + 1, options).C_mi;
    const Mat3 C_ri = config.ImuPose(config.input_imu).rotation();
    if (!C_ri.isIdentity(0.0)) *C_mi = C_ri * *C_mi;
  } catch (const std::exception& e) {
    *message = std::string("gravity initialisation failed: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace ctlio::lio
