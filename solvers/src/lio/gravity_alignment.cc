#include "ctlio/solvers/lio/gravity_alignment.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
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
  // Too few samples in the window is a rate (or start) problem, not a units one: a 20 Hz IMU gives
  // 4 samples in 0.2 s, whose mean the magnitude gate below would blame on the accelerometer's
  // units or axes, and imu::InitializeGravity on the platform's motion. Named first, with the rate.
  constexpr int kMinSamples = 10;  // imu::InitializeGravity's min_samples below
  int in_window = 0;
  for (const ImuSample& s : samples) in_window += s.t_ns >= t0_ns && s.t_ns <= end_ns;
  if (in_window < kMinSamples) {
    std::ostringstream m;
    m.precision(3);
    m << "gravity initialisation: only " << in_window << " IMU samples in the "
      << 1e-9 * double(end_ns - t0_ns) << " s before the first scan end (need " << kMinSamples
      << "): ";
    const double span_s = 1e-9 * double(samples.back().t_ns - samples.front().t_ns);
    const double rate = samples.size() > 1 && span_s > 0 ? double(samples.size() - 1) / span_s : 0;
    const double needed = kMinSamples / std::max(config.gravity_init_duration, 1e-9);
    if (samples.size() < 2) {
      m << "the IMU rate is too low (a single sample in the "
        << 1e-9 * double(end_ns - samples.front().t_ns) << " s before the first scan end; needs "
        << needed << " Hz for init.gravity_duration = " << config.gravity_init_duration << " s)";
    } else if (rate < needed) {
      m << "the IMU rate (about " << rate
        << " Hz) is too low for init.gravity_duration = " << config.gravity_init_duration
        << " s (needs " << needed << " Hz; a longer init.gravity_duration lowers that)";
    } else {
      m << "the IMU starts only " << 1e-9 * double(end_ns - samples.front().t_ns)
        << " s before the first scan end (rate about " << rate << " Hz)";
    }
    *message = m.str();
    return false;
  }
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
  options.min_samples = kMinSamples;
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
