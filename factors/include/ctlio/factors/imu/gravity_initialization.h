// Gravity initialisation (SPEC §3): the rotation C_mi from a gravity-aligned
// frame i (z up, g_i = [0, 0, −|g|]) into the map frame, estimated from the
// first accelerometer samples while the platform is still.
//
// The map frame is the robot (IMU) frame at start-up, C_rm = I. At rest the
// accelerometer reads f = −C_rm C_mi g_i = C_mi [0, 0, |g|]ᵀ, so the mean
// reading fixes roll and pitch of C_im = C_miᵀ = R_y(pitch)·R_x(roll) (yaw is
// unobservable and set to 0):
//   roll = atan2(f_y, f_z),   pitch = atan2(−f_x, √(f_y² + f_z²)).
// The samples are rejected — std::runtime_error saying which test failed and
// by how much — when the platform is not still enough. A multicopter on the
// ground vibrates (EuRoC: 1.1 m/s² RMS and 0.3 rad/s peaks with the rotors
// spinning while the ground truth moves < 1 cm/s), so stillness is judged on
// block means over `block_ns` (0.1 s): rigid-body motion shows as block means
// of f that wander from the overall mean, or as a block-mean turn rate; the
// raw scatter only has a loose limit.
#pragma once

#include <vector>

#include "ctlio/factors/imu/imu_data.h"

namespace ctlio::imu {

struct GravityInitializationOptions {
  double gravity = 9.81;                   // |g| in m/s²
  std::int64_t block_ns = 100'000'000;     // averaging block for the stillness tests
  double max_block_accel_deviation = 0.4;  // max |block mean f − f̄|, m/s²
  double max_block_gyro_rate = 0.2;        // max |block mean ω_m| (bias included), rad/s
  double max_accel_std = 2.0;              // RMS deviation of raw f from f̄, m/s²
  double max_gravity_error = 0.3;          // ||f̄| − |g||, m/s²
  int min_samples = 20;
  // Accelerometer bias removed from the readings first, if known (sensor
  // frame); zero at a cold start.
  Vec3 accel_bias = Vec3::Zero();
};

struct GravityInitialization {
  Mat3 C_mi = Mat3::Identity();
  double roll = 0.0;   // rad
  double pitch = 0.0;  // rad
  Vec3 mean_accel = Vec3::Zero();
  double accel_std = 0.0;  // raw RMS scatter
  double max_block_accel_deviation = 0.0;
  double max_block_gyro_rate = 0.0;
};

// Uses all samples with t in [t0_ns, t0_ns + duration_ns). The sensor→robot
// rotation C_bs (identity for EuRoC) is applied to the readings first.
GravityInitialization InitializeGravity(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                                        std::int64_t duration_ns,
                                        const GravityInitializationOptions& options = {},
                                        const Mat3& C_body_sensor = Mat3::Identity());

// Angle between the gravity directions (the tilt error) of two roll/pitch
// estimates, robot frame: the quantity gravity initialisation observes. Roll
// alone is ill-conditioned near pitch ±90° (its error grows like 1/cos(pitch)).
double TiltError(const Mat3& C_mi, const Mat3& C_wb_truth);

// The same error as a rotation vector in the (z-up) world frame: δ = Log(C_est C_wb_truthᵀ) for
// the attitude C_est that has the estimated gravity direction and is closest to the truth (the
// unobservable yaw taken from the truth). δ_z = 0 by construction; δ_x and δ_y are the errors
// about the world x and y axes — roll and pitch measured about fixed horizontal axes, well
// conditioned at every attitude — and |δ| = TiltError. To first order δ equals the horizontal
// part of Log(C_euler C_wb_truthᵀ), C_euler = R_z(yaw_truth)R_y(pitch_est)R_x(roll_est).
Vec3 TiltErrorVector(const Mat3& C_mi, const Mat3& C_wb_truth);

// Roll and pitch (ZYX Euler, C = R_z(yaw)R_y(pitch)R_x(roll)) of a body → world
// rotation in a z-up world: the reference the estimate is compared with.
void RollPitch(const Mat3& C_wb, double* roll, double* pitch);

}  // namespace ctlio::imu
