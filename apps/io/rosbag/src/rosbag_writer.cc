#include <nav_msgs/Odometry.h>
#include <ros/exception.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

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
    uint32_t point_step = 0;
    const std::vector<PointField> fields = OusterFields(&point_step);
    TimeConvention ouster;
    ouster.field = "t";
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
        m.linear_acceleration.x = s.accel.x();
        m.linear_acceleration.y = s.accel.y();
        m.linear_acceleration.z = s.accel.z();
        bag.write(options.imu_topic, m.header.stamp, m);
      }
      // Stamp = scan start, as the Ouster driver does; recorded at the scan end (when a driver
      // would publish it).
      frame.cloud.stamp_ns = frame.start_ns;
      const auto msg =
          EncodePointCloud2(frame.cloud, fields, point_step, ouster, options.lidar_frame);
      bag.write(options.lidar_topic, RosTime(frame.end_ns), msg);
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
  WriteOdometryBag(path, trajectory, std::vector<std::array<double, 36>>(trajectory.size()), topic,
                   frame, child_frame);
}

void WriteOdometryBag(const std::string& path, const std::vector<StampedPose>& trajectory,
                      const std::vector<std::array<double, 36>>& pose_covariances,
                      const std::string& topic, const std::string& frame,
                      const std::string& child_frame) {
  if (pose_covariances.size() != trajectory.size()) {
    throw std::invalid_argument(path + ": " + std::to_string(pose_covariances.size()) +
                                " pose covariances for " + std::to_string(trajectory.size()) +
                                " poses");
  }
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (size_t k = 0; k < trajectory.size(); ++k) {
      auto o = OdometryMsg(trajectory[k], frame, child_frame);
      for (size_t i = 0; i < 36; ++i) o.pose.covariance[i] = pose_covariances[k][i];
      bag.write(topic, o.header.stamp, o);
    }
    bag.close();
  } catch (const ros::Exception& e) {
    throw std::runtime_error(path + ": cannot write the bag: " + e.what());
  }
}

}  // namespace ctlio::io
