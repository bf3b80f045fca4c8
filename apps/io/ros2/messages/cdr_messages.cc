#include "ctlio/io/cdr_messages.h"

#include <stdexcept>

namespace ctlio::io::ros2 {
namespace {

// Lower bounds of an element's bytes on the wire (padding only adds), for CdrReader::Count:
// PointField: name length + offset + datatype + count; TransformStamped: stamp, two string
// lengths, 7 float64.
constexpr size_t kMinPointFieldBytes = 4 + 4 + 1 + 4;
constexpr size_t kMinTransformStampedBytes = 8 + 4 + 4 + 7 * 8;

void ReadTime(CdrReader& in, ros::Time* t) {
  const int32_t sec = in.I32("header.stamp.sec");
  const uint32_t nsec = in.U32("header.stamp.nanosec");
  if (sec < 0) in.Fail("stamp sec " + std::to_string(sec) + " is before 1970");
  if (nsec >= 1'000'000'000u) in.Fail("stamp nanosec " + std::to_string(nsec) + " ≥ 10⁹");
  t->sec = uint32_t(sec);
  t->nsec = nsec;
}

void ReadVector(CdrReader& in, const char* what, double* x, double* y, double* z) {
  *x = in.F64(what);
  *y = in.F64(what);
  *z = in.F64(what);
}

void ReadQuaternion(CdrReader& in, const char* what, geometry_msgs::Quaternion* q) {
  q->x = in.F64(what);
  q->y = in.F64(what);
  q->z = in.F64(what);
  q->w = in.F64(what);
}

template <class Array>
void ReadArray(CdrReader& in, const char* what, Array* a) {
  for (double& v : *a) v = in.F64(what);
}

void ReadPose(CdrReader& in, geometry_msgs::Pose* p) {
  ReadVector(in, "pose.position", &p->position.x, &p->position.y, &p->position.z);
  ReadQuaternion(in, "pose.orientation", &p->orientation);
}

void WriteTime(CdrWriter& out, const ros::Time& t) {
  if (t.sec > uint32_t(INT32_MAX)) {
    throw std::runtime_error("time " + std::to_string(t.sec) +
                             " s does not fit ROS 2's int32 seconds");
  }
  out.I32(int32_t(t.sec));
  out.U32(t.nsec);
}

void WriteVector(CdrWriter& out, double x, double y, double z) {
  out.F64(x);
  out.F64(y);
  out.F64(z);
}

void WriteQuaternion(CdrWriter& out, const geometry_msgs::Quaternion& q) {
  out.F64(q.x);
  out.F64(q.y);
  out.F64(q.z);
  out.F64(q.w);
}

template <class Array>
void WriteArray(CdrWriter& out, const Array& a) {
  for (double v : a) out.F64(v);
}

void WritePose(CdrWriter& out, const geometry_msgs::Pose& p) {
  WriteVector(out, p.position.x, p.position.y, p.position.z);
  WriteQuaternion(out, p.orientation);
}

uint32_t Size32(size_t n, const char* what) {
  if (n > UINT32_MAX) throw std::runtime_error(std::string(what) + ": too many elements for CDR");
  return uint32_t(n);
}

}  // namespace

void ReadHeader(CdrReader& in, std_msgs::Header* h) {
  h->seq = 0;
  ReadTime(in, &h->stamp);
  h->frame_id = in.String("header.frame_id");
}

void WriteHeader(CdrWriter& out, const std_msgs::Header& h) {
  WriteTime(out, h.stamp);
  out.String(h.frame_id);
}

std::string Ros1TypeName(const std::string& ros2_type) {
  const size_t at = ros2_type.find("/msg/");
  if (at == std::string::npos || at == 0 || ros2_type.find('/', at + 5) != std::string::npos) {
    return ros2_type;
  }
  return ros2_type.substr(0, at) + "/" + ros2_type.substr(at + 5);
}

std::string Ros2TypeName(const std::string& ros1_type) {
  const size_t at = ros1_type.find('/');
  if (at == std::string::npos || at == 0 || ros1_type.find('/', at + 1) != std::string::npos) {
    return ros1_type;
  }
  return ros1_type.substr(0, at) + "/msg/" + ros1_type.substr(at + 1);
}

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               sensor_msgs::PointCloud2* msg) {
  CdrReader in(data, size, where, "sensor_msgs/msg/PointCloud2");
  ReadHeader(in, &msg->header);
  msg->height = in.U32("height");
  msg->width = in.U32("width");
  const uint32_t n = in.Count("fields", kMinPointFieldBytes);
  msg->fields.clear();
  msg->fields.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    sensor_msgs::PointField f;
    f.name = in.String("fields.name");
    f.offset = in.U32("fields.offset");
    f.datatype = in.U8("fields.datatype");
    f.count = in.U32("fields.count");
    msg->fields.push_back(std::move(f));
  }
  msg->is_bigendian = in.Bool("is_bigendian");
  msg->point_step = in.U32("point_step");
  msg->row_step = in.U32("row_step");
  in.Bytes(in.Count("data", 1), "data", &msg->data);
  msg->is_dense = in.Bool("is_dense");
  in.Finish();
}

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, sensor_msgs::Imu* msg) {
  CdrReader in(data, size, where, "sensor_msgs/msg/Imu");
  ReadHeader(in, &msg->header);
  ReadQuaternion(in, "orientation", &msg->orientation);
  ReadArray(in, "orientation_covariance", &msg->orientation_covariance);
  auto& w = msg->angular_velocity;
  ReadVector(in, "angular_velocity", &w.x, &w.y, &w.z);
  ReadArray(in, "angular_velocity_covariance", &msg->angular_velocity_covariance);
  auto& a = msg->linear_acceleration;
  ReadVector(in, "linear_acceleration", &a.x, &a.y, &a.z);
  ReadArray(in, "linear_acceleration_covariance", &msg->linear_acceleration_covariance);
  in.Finish();
}

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               tf2_msgs::TFMessage* msg) {
  CdrReader in(data, size, where, "tf2_msgs/msg/TFMessage");
  const uint32_t n = in.Count("transforms", kMinTransformStampedBytes);
  msg->transforms.clear();
  msg->transforms.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    geometry_msgs::TransformStamped t;
    ReadHeader(in, &t.header);
    t.child_frame_id = in.String("child_frame_id");
    auto& p = t.transform.translation;
    ReadVector(in, "transform.translation", &p.x, &p.y, &p.z);
    ReadQuaternion(in, "transform.rotation", &t.transform.rotation);
    msg->transforms.push_back(std::move(t));
  }
  in.Finish();
}

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               nav_msgs::Odometry* msg) {
  CdrReader in(data, size, where, "nav_msgs/msg/Odometry");
  ReadHeader(in, &msg->header);
  msg->child_frame_id = in.String("child_frame_id");
  ReadPose(in, &msg->pose.pose);
  ReadArray(in, "pose.covariance", &msg->pose.covariance);
  auto& v = msg->twist.twist;
  ReadVector(in, "twist.linear", &v.linear.x, &v.linear.y, &v.linear.z);
  ReadVector(in, "twist.angular", &v.angular.x, &v.angular.y, &v.angular.z);
  ReadArray(in, "twist.covariance", &msg->twist.covariance);
  in.Finish();
}

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where,
               geometry_msgs::PoseStamped* msg) {
  CdrReader in(data, size, where, "geometry_msgs/msg/PoseStamped");
  ReadHeader(in, &msg->header);
  ReadPose(in, &msg->pose);
  in.Finish();
}

std::vector<uint8_t> EncodeCdr(const sensor_msgs::PointCloud2& msg, CdrEndian endian) {
  CdrWriter out(endian);
  WriteHeader(out, msg.header);
  out.U32(msg.height);
  out.U32(msg.width);
  out.U32(Size32(msg.fields.size(), "PointCloud2 fields"));
  for (const auto& f : msg.fields) {
    out.String(f.name);
    out.U32(f.offset);
    out.U8(f.datatype);
    out.U32(f.count);
  }
  out.Bool(msg.is_bigendian);
  out.U32(msg.point_step);
  out.U32(msg.row_step);
  out.Bytes(msg.data);
  out.Bool(msg.is_dense);
  return out.Take();
}

std::vector<uint8_t> EncodeCdr(const sensor_msgs::Imu& msg, CdrEndian endian) {
  CdrWriter out(endian);
  WriteHeader(out, msg.header);
  WriteQuaternion(out, msg.orientation);
  WriteArray(out, msg.orientation_covariance);
  const auto& w = msg.angular_velocity;
  WriteVector(out, w.x, w.y, w.z);
  WriteArray(out, msg.angular_velocity_covariance);
  const auto& a = msg.linear_acceleration;
  WriteVector(out, a.x, a.y, a.z);
  WriteArray(out, msg.linear_acceleration_covariance);
  return out.Take();
}

std::vector<uint8_t> EncodeCdr(const tf2_msgs::TFMessage& msg, CdrEndian endian) {
  CdrWriter out(endian);
  out.U32(Size32(msg.transforms.size(), "TFMessage transforms"));
  for (const auto& t : msg.transforms) {
    WriteHeader(out, t.header);
    out.String(t.child_frame_id);
    const auto& p = t.transform.translation;
    WriteVector(out, p.x, p.y, p.z);
    WriteQuaternion(out, t.transform.rotation);
  }
  return out.Take();
}

std::vector<uint8_t> EncodeCdr(const nav_msgs::Odometry& msg, CdrEndian endian) {
  CdrWriter out(endian);
  WriteHeader(out, msg.header);
  out.String(msg.child_frame_id);
  WritePose(out, msg.pose.pose);
  WriteArray(out, msg.pose.covariance);
  const auto& v = msg.twist.twist;
  WriteVector(out, v.linear.x, v.linear.y, v.linear.z);
  WriteVector(out, v.angular.x, v.angular.y, v.angular.z);
  WriteArray(out, msg.twist.covariance);
  return out.Take();
}

std::vector<uint8_t> EncodeCdr(const geometry_msgs::PoseStamped& msg, CdrEndian endian) {
  CdrWriter out(endian);
  WriteHeader(out, msg.header);
  WritePose(out, msg.pose);
  return out.Take();
}

}  // namespace ctlio::io::ros2
