#include <nav_msgs/Odometry.h>
#include <ros/exception.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <stdexcept>

#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {
namespace {

ros::Time RosTime(int64_t ns) {
  // ros::TIME_MIN is 1 ns: a bag cannot hold time 0 (the simulator's default start).
  if (ns < 1) {
    throw std::runtime_error(
        "time " + std::to_string(ns) +
        " ns: a ROS 1 bag holds times from 1 ns on (start the sequence later)");
  }
  ros::Time t;
  t.fromNSec(uint64_t(ns));
  return t;
}

void ToRos(const SE3& T, geometry_msgs::Quaternion* q, double* x, double* y, double* z) {
  const Eigen::Quaterniond r(T.rotation());
  q->w = r.w();
  q->x = r.x();
  q->y = r.y();
  q->z = r.z();
  *x = T.translation().x();
  *y = T.translation().y();
  *z = T.translation().z();
}

nav_msgs::Odometry OdometryMsg(const StampedPose& p, const std::string& frame,
                               const std::string& child) {
  nav_msgs::Odometry o;
  o.header.stamp = RosTime(p.t_ns);
  o.header.frame_id = frame;
  o.child_frame_id = child;
  auto& q = o.pose.pose;
  ToRos(p.pose, &q.orientation, &q.position.x, &q.position.y, &q.position.z);
  return o;
}

}  // namespace

size_t WriteRosbag(DataSource& source, const std::string& path, const RosbagWriteOptions& options,
                   const std::function<void(size_t, size_t)>& progress) {
  RequireFirstImuInBodyFrame(source, path + " (ROS bag)");
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    if (options.compression == "lz4") {
      bag.setCompression(rosbag::compression::LZ4);
    } else if (options.compression == "bz2") {
      bag.setCompression(rosbag::compression::BZ2);
    } else if (options.compression != "none") {
      throw std::runtime_error(path + ": unknown bag compression '" + options.compression +
                               "' (none, lz4, bz2)");
    }
    if (!(options.accel_unit > 0.0)) throw std::runtime_error(path + ": accel_unit must be > 0");
    uint32_t point_step = 0;
    const std::vector<PointField> fields = DriverFields(options.point_format, &point_step);
    const TimeConvention time = DriverTime(options.point_format);
    ScanFrame frame;
    size_t n = 0;
    bool first = true;
    while (source.Next(&frame)) {
      if (first && options.write_tf_static) {
        // Latched static transform, stamped with the first data so that players keep it.
        tf2_msgs::TFMessage tf;
        geometry_msgs::TransformStamped e;
        e.header.stamp = RosTime(frame.start_ns);
        e.header.frame_id = options.imu_frame;
        e.child_frame_id = options.lidar_frame;
        auto& tr = e.transform;
        ToRos(source.ImuFromLidar(), &tr.rotation, &tr.translation.x, &tr.translation.y,
              &tr.translation.z);
        tf.transforms.push_back(e);
        bag.write("/tf_static", e.header.stamp, tf);
      }
      first = false;
      for (const ImuSample& s : frame.imu) {
        if (s.imu != 0) continue;  // one IMU topic: the first IMU (Imus()[0])
        sensor_msgs::Imu m;
        m.header.stamp = RosTime(s.t_ns);
        m.header.frame_id = options.imu_frame;
        m.orientation_covariance[0] = -1.0;  // sensor_msgs/Imu: no orientation estimate
        m.angular_velocity.x = s.gyro.x();
        m.angular_velocity.y = s.gyro.y();
        m.angular_velocity.z = s.gyro.z();
        m.linear_acceleration.x = s.accel.x() / options.accel_unit;
        m.linear_acceleration.y = s.accel.y() / options.accel_unit;
        m.linear_acceleration.z = s.accel.z() / options.accel_unit;
        bag.write(options.imu_topic, m.header.stamp, m);
      }
      // Stamp = scan start as the Ouster, Hesai and Livox drivers do (Velodyne's: the scan end);
      // recorded at the scan end (when a driver would publish it).
      frame.cloud.stamp_ns = time.stamp_at == StampAt::kScanEnd ? frame.end_ns : frame.start_ns;
      RosTime(frame.cloud.stamp_ns);  // a time the bag can hold (checked before encoding)
      if (options.point_format == PointFormat::kLivoxCustomMsg) {
        bag.write(options.lidar_topic, RosTime(frame.end_ns),
                  livox::FromPointCloud(frame.cloud, options.lidar_frame));
      } else {
        const auto msg =
            EncodePointCloud2(frame.cloud, fields, point_step, time, options.lidar_frame);
        bag.write(options.lidar_topic, RosTime(frame.end_ns), msg);
      }
      ++n;
      if (progress) progress(n, source.NumScans());
    }
    if (options.write_ground_truth) {
      if (const auto gt = source.GroundTruth()) {
        for (const StampedPose& p : *gt) {
          const auto o = OdometryMsg(p, "world", options.lidar_frame);
          bag.write("/ground_truth", o.header.stamp, o);
        }
      }
    }
    bag.close();
    return n;
  } catch (const ros::Exception& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::string& topic, const std::string& frame,
                      const std::string& child_frame) {
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (const StampedPose& p : trajectory) {
      const auto o = OdometryMsg(p, frame, child_frame);
      bag.write(topic, o.header.stamp, o);
    }
    bag.close();
  } catch (const ros::Exception& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

}  // namespace ctlio::io
