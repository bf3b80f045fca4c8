// Gravity initialisation of the odometry (SPEC §3): C_mi from the accelerometer while the
// platform is still at the start (imu::InitializeGravity, which also judges stillness). The map
// frame is the robot frame at the start, so the initialisation's C_mi is the map's.
#pragma once

#include <string>

#include "ctlio/solvers/lio/imu_buffer.h"
#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// Uses the last config.gravity_init_duration seconds of IMU up to t_end (odometry seconds, the
// first scan's end). Returns false with a message (no samples, not still, and — for the methods
// that use the accelerometer — a mean specific force not within config.input.gravity_tolerance of
// config.gravity: units or axes that cannot be right) instead of throwing.
bool InitialiseGravity(const ImuBuffer& imu, double t_end, const OdometryConfig& config, Mat3* C_mi,
                       std::string* message);

}  // namespace ctlio::lio
