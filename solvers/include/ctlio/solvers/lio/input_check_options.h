// Thresholds of the odometry's input gates (input_checks.h; SPEC §5 inputs, SPEC §1 units), part
// of OdometryConfig (`input:` section of an odometry YAML) so that every LioOdometry applies them,
// whoever feeds it. Defaults: physical limits of common MEMS IMUs and lidar drivers, loose enough
// that real data never trip them (data/*.yaml document each key).
#pragma once

namespace ctlio::lio {

struct InputCheckOptions {
  double max_gyro = 35.0;              // rad/s (2000 °/s, the usual MEMS full scale)
  double max_accel = 160.0;            // m/s² (16 g)
  double gravity_tolerance = 0.2;      // relative error of |mean specific force| at initialisation
  double constant_imu_duration = 0.5;  // s of bit-identical IMU output that counts as frozen
  double moving_translation = 0.05;    // m between scan ends: "the lidar moves"
  double moving_rotation = 0.02;       // rad between scan ends
  double scan_time_tolerance = 0.01;   // s a point may lie outside its scan's interval
  // Readers (not the odometry): an IMU gap longer than this is an error (file and line); 0 = off,
  // gaps are warnings and the odometry bridges them (it flags the scans by
  // OdometryConfig::max_imu_gap).
  double max_imu_gap_error = 0.0;  // s
  // ROS bag readers (not the odometry): the accelerometer's readings are multiplied by this to
  // give m/s² (sensor_msgs/Imu's unit); 9.80665 for drivers that publish g (Livox's built-in IMU),
  // so that a sensor's config is self-contained. ctlio_odometry --imu_accel_scale, given
  // explicitly, wins; dataset folders and the simulator are in m/s² and ignore it.
  double accel_scale = 1.0;
  // Strict input (docs/user-guide/bad-input.md): every recovery of the readers and of these gates
  // is an error naming the defect, for pipelines that must not guess. ctlio_odometry --strict
  // (given explicitly) wins over it; programs apply it with io::WarningLimiter::SetStrict.
  bool strict = false;

  void Validate() const;  // throws std::invalid_argument naming the field
};

}  // namespace ctlio::lio
