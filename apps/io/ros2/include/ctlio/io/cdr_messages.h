// The ROS 2 messages ctlio reads and writes, in CDR (cdr.h), to and from the ROS 1 C++ message
// structs of Debian's ROS 1 headers, so that a ROS 2 bag goes through the same checks and
// conversions as a ROS 1 bag (pointcloud2.h, rosbag_source.h). Layouts from the ROS 2 interface
// definitions (common_interfaces, geometry2, rcl_interfaces):
//   builtin_interfaces/msg/Time: int32 sec, uint32 nanosec
//   std_msgs/msg/Header: Time stamp, string frame_id (no seq: 0 in the ROS 1 struct)
//   sensor_msgs/msg/PointField: string name, uint32 offset, uint8 datatype, uint32 count
//   sensor_msgs/msg/PointCloud2: Header, uint32 height, uint32 width, PointField[] fields,
//     bool is_bigendian, uint32 point_step, uint32 row_step, uint8[] data, bool is_dense
//   sensor_msgs/msg/Imu: Header, Quaternion orientation, float64[9] orientation_covariance,
//     Vector3 angular_velocity, float64[9] ..., Vector3 linear_acceleration, float64[9] ...
//   geometry_msgs/msg/TransformStamped: Header, string child_frame_id, Transform (Vector3
//     translation, Quaternion rotation); tf2_msgs/msg/TFMessage: TransformStamped[] transforms
//   nav_msgs/msg/Odometry: Header, string child_frame_id, PoseWithCovariance (Pose, float64[36]),
//     TwistWithCovariance (Twist (Vector3 linear, Vector3 angular), float64[36])
//   geometry_msgs/msg/PoseStamped: Header, Pose (Point position, Quaternion orientation)
// (Quaternion: float64 x, y, z, w; Vector3 and Point: float64 x, y, z.)
//
// Decoding errors: std::runtime_error "<where>corrupt <ROS 2 type> message: <what>"; a stamp
// before 1970 (negative seconds, which ROS 1's unsigned time cannot hold) or with nanosec ≥ 10⁹
// is corrupt too. Encoding a time past 2038 (ROS 2's int32 seconds) throws.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/io/cdr.h"

namespace ctlio::io::ros2 {

// "sensor_msgs/msg/PointCloud2" ↔ "sensor_msgs/PointCloud2" (any "<package>/msg/<Name>"); a name
// of another shape is returned unchanged.
std::string Ros1TypeName(const std::string& ros2_type);
std::string Ros2TypeName(const std::string& ros1_type);

// std_msgs/msg/Header, for the messages defined elsewhere (cdr_livox.h).
void ReadHeader(CdrReader& in, std_msgs::Header* header);
void WriteHeader(CdrWriter& out, const std_msgs::Header& header);

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               sensor_msgs::PointCloud2* msg);
void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, sensor_msgs::Imu* msg);
void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               tf2_msgs::TFMessage* msg);
void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, nav_msgs::Odometry* msg);
void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               geometry_msgs::PoseStamped* msg);

std::vector<uint8_t> EncodeCdr(const sensor_msgs::PointCloud2& msg,
                               CdrEndian endian = CdrEndian::kLittle);
std::vector<uint8_t> EncodeCdr(const sensor_msgs::Imu& msg, CdrEndian endian = CdrEndian::kLittle);
std::vector<uint8_t> EncodeCdr(const tf2_msgs::TFMessage& msg,
                               CdrEndian endian = CdrEndian::kLittle);
std::vector<uint8_t> EncodeCdr(const nav_msgs::Odometry& msg,
                               CdrEndian endian = CdrEndian::kLittle);
std::vector<uint8_t> EncodeCdr(const geometry_msgs::PoseStamped& msg,
                               CdrEndian endian = CdrEndian::kLittle);

}  // namespace ctlio::io::ros2
