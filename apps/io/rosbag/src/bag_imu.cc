// BagSource: one sensor_msgs/Imu into the IMU stream (duplicates, time order, gaps, unit), and
// the totals of the recoveries logged at the end of the bag.
#include <glog/logging.h>

#include <stdexcept>

#include "bag_source_impl.h"

namespace ctlio::io {

void BagSource::Impl::AddImu(const sensor_msgs::Imu& m) {
  ++imu_messages;
  const int64_t t = int64_t(m.header.stamp.toNSec());
  if (t == last_imu_ns) {
    // Counted by the limiter as in the folder readers: reported in the run's input defects and
    // an error under --strict (it used to be a log line only).
    ++duplicates;
    if (warnings->Count("duplicate IMU time", Where(imu_topic, imu_messages) + "IMU time " +
                                                  std::to_string(t) + " ns repeated")) {
      LOG(WARNING) << Where(imu_topic, imu_messages) << "duplicate IMU time; sample dropped";
    }
    return;
  }
  if (t < last_imu_ns) {
    throw std::runtime_error(Where(imu_topic, imu_messages) + "IMU time goes backwards (" +
                             std::to_string(t) + " ns after " + std::to_string(last_imu_ns) +
                             " ns)");
  }
  if (last_imu_ns != INT64_MIN && t - last_imu_ns > options.imu_gap_warning_ns) {
    const double gap = 1e-9 * double(t - last_imu_ns);
    // Opt-in error; by default the samples are handed on and the odometry bridges the hole
    // (docs/user-guide/bad-input.md).
    if (options.max_imu_gap_ns > 0 && t - last_imu_ns > options.max_imu_gap_ns) {
      throw std::runtime_error(Where(imu_topic, imu_messages) + "gap of " + std::to_string(gap) +
                               " s in the IMU (limit " +
                               std::to_string(1e-9 * double(options.max_imu_gap_ns)) + " s)");
    }
    if (warnings->Count("IMU gap",
                        Where(imu_topic, imu_messages) + "gap of " + std::to_string(gap) + " s")) {
      LOG(WARNING) << Where(imu_topic, imu_messages) << "gap of " << gap
                   << " s in the IMU; samples handed on";
    }
  }
  last_imu_ns = t;
  ImuSample s;
  s.t_ns = t;
  s.gyro = Vec3(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z);
  s.accel = options.accel_scale *
            Vec3(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z);
  // Plausibility (finiteness, physical range) is the odometry's input gate (ImuBuffer::AddImu),
  // one place for every reader: a non-finite sample is rejected and counted there.
  // sensor_msgs/Imu is m/s², but some drivers publish g (Livox's built-in IMU): a mean specific
  // force near 1 over the first samples is flagged once, with the remedy.
  if (imu_messages <= 200) {
    accel_norm_sum += s.accel.norm();
    if (imu_messages == 200 && accel_norm_sum / 200 > 0.5 && accel_norm_sum / 200 < 1.5) {
      LOG(WARNING) << path << ": " << imu_topic << ": mean |accelerometer| over the first 200 "
                   << "samples is " << accel_norm_sum / 200 << ": the IMU seems to report g, not "
                   << "m/s²; scale it with input.accel_scale: 9.80665 in the config or "
                   << "--imu_accel_scale=9.80665";
    }
  }
  imu.push_back(s);
}

void BagSource::Impl::LogTotals() {
  warnings->LogTotals();
  if (duplicates > 0) {
    LOG(WARNING) << path << ": dropped " << duplicates << " duplicate IMU sample(s)";
  }
  if (retimed_scans > 0) {
    LOG(WARNING) << path << ": " << lidar_topic << ": " << retimed_scans
                 << " scan(s) whose per-point times were not a sweep (rescaled or recovered "
                 << "from the azimuth)";
  }
  if (points_outside_sweep > 0) {
    LOG(WARNING) << path << ": " << lidar_topic << ": dropped " << points_outside_sweep
                 << " point(s) timed more than a scan period from their scan's stamp";
  }
  if (unusable_scans > 0) {
    LOG(WARNING) << path << ": " << lidar_topic << ": " << unusable_scans
                 << " unusable scan(s) (empty, all non-finite or all at one instant) handed on "
                 << "with their nominal interval";
  }
}

}  // namespace ctlio::io
