// The messages of any DataSource as a bag holds them (bag_writer.h), for both bag kinds.
#include "ctlio/io/bag_writer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>

#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/pointcloud2.h"

namespace ctlio::io {
namespace {

ros::Time RosTime(int64_t ns) {
  if (ns < 0) {
    throw std::runtime_error("time " + std::to_string(ns) + " ns: bags hold no times before 1970");
  }
  ros::Time t;
  t.sec = uint32_t(ns / 1'000'000'000);
  t.nsec = uint32_t(ns % 1'000'000'000);
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

void WriteOdometryMessages(const std::vector<StampedPose>& trajectory,
                           const std::vector<std::array<double, 36>>& pose_covariances,
                           const std::string& topic, const std::string& frame,
                           const std::string& child_frame, BagMessageSink& sink) {
  if (!pose_covariances.empty() && pose_covariances.size() != trajectory.size()) {
    throw std::invalid_argument(std::to_string(pose_covariances.size()) + " pose covariances for " +
                                std::to_string(trajectory.size()) + " poses");
  }
  for (size_t k = 0; k < trajectory.size(); ++k) {
    nav_msgs::Odometry o = OdometryMsg(trajectory[k], frame, child_frame);
    if (!pose_covariances.empty()) {
      for (size_t i = 0; i < 36; ++i) o.pose.covariance[i] = pose_covariances[k][i];
    }
    sink.Write(topic, trajectory[k].t_ns, o);
  }
}

size_t WriteBagMessages(DataSource& source, BagMessageSink& sink, const RosbagWriteOptions& options,
                        const std::function<void(size_t, size_t)>& progress) {
  if (!(options.accel_unit > 0.0)) throw std::runtime_error("bag writer: accel_unit must be > 0");
  uint32_t point_step = 0;
  const std::vector<PointField> fields = DriverFields(options.point_format, &point_step);
  const TimeConvention time = DriverTime(options.point_format);
  // Ground truth interleaved in time order (the header comment of bag_writer.h); a source that
  // knows its ground truth only at the end gets it written there.
  std::vector<StampedPose> truth;
  if (options.write_ground_truth) {
    if (const auto gt = source.GroundTruth()) truth = *gt;
  }
  size_t next_truth = 0;
  auto truth_until = [&](int64_t t_ns) {
    for (; next_truth < truth.size() && truth[next_truth].t_ns <= t_ns; ++next_truth) {
      const StampedPose& p = truth[next_truth];
      sink.Write("/ground_truth", p.t_ns, OdometryMsg(p, "world", options.lidar_frame));
    }
  };
  ScanFrame frame;
  size_t n = 0;
  bool first = true;
  while (source.Next(&frame)) {
    if (first && options.write_tf_static) {
      // Latched static transform, stamped with the first data so that players keep it.
      int64_t t = frame.start_ns;
      for (const ImuSample& s : frame.imu) t = std::min(t, s.t_ns);
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped e;
      e.header.stamp = RosTime(t);
      e.header.frame_id = options.imu_frame;
      e.child_frame_id = options.lidar_frame;
      auto& tr = e.transform;
      ToRos(source.ImuFromLidar(), &tr.rotation, &tr.translation.x, &tr.translation.y,
            &tr.translation.z);
      tf.transforms.push_back(e);
      sink.Write("/tf_static", t, tf);
    }
    first = false;
    for (const ImuSample& s : frame.imu) {
      if (s.imu != 0) continue;  // one IMU topic: the first IMU (Imus()[0])
      truth_until(s.t_ns);
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
      sink.Write(options.imu_topic, s.t_ns, m);
    }
    // Stamp = scan start as the Ouster, Hesai and Livox drivers do (Velodyne's: the scan end);
    // recorded at the scan end (when a driver would publish it).
    frame.cloud.stamp_ns = time.stamp_at == StampAt::kScanEnd ? frame.end_ns : frame.start_ns;
    RosTime(frame.cloud.stamp_ns);  // (a time before 1970 is an error here, not a wrapped stamp)
    truth_until(frame.end_ns);
    if (options.point_format == PointFormat::kLivoxCustomMsg) {
      sink.Write(options.lidar_topic, frame.end_ns,
                 livox::FromPointCloud(frame.cloud, options.lidar_frame));
    } else {
      sink.Write(options.lidar_topic, frame.end_ns,
                 EncodePointCloud2(frame.cloud, fields, point_step, time, options.lidar_frame));
    }
    ++n;
    if (progress) progress(n, source.NumScans());
  }
  if (options.write_ground_truth && truth.empty()) {
    if (const auto gt = source.GroundTruth()) truth = *gt;
  }
  truth_until(INT64_MAX);
  return n;
}

}  // namespace ctlio::io
