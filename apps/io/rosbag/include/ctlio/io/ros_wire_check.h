// Checks of the ROS 1 wire format of the messages ctlio reads whose deserialiser allocates from a
// count in the bytes: roscpp_serialization resizes a vector to its 32-bit length BEFORE it checks
// that the message holds that many elements, so one corrupt length inside a message that passes
// the bag's record-structure check (bag_structure.h) is a 4 GB allocation (PointCloud2 `data`) or
// a bare std::bad_alloc (4e9 PointField or TransformStamped elements). The walk below bounds every
// length by the bytes left in the message, then the message is deserialised from the same bytes.
// Imu and Odometry hold no variable-length array (strings are checked by the library before it
// allocates) and need no walk.
#pragma once

#include <ros/serialization.h>
#include <rosbag/message_instance.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::io {

// Throw std::runtime_error "<where>corrupt <type> message: <what>" (where: bag, topic, message
// index) when a length or count does not fit the `size` bytes, or bytes are left over.
void CheckPointCloud2Wire(const uint8_t* data, size_t size, const std::string& where);
void CheckTfMessageWire(const uint8_t* data, size_t size, const std::string& where);

// The message `m` as M after `check` (one of the above, or null for types without arrays): its
// bytes are read once, checked and deserialised. A type or md5sum other than M's is an error
// naming `where`, not a null pointer.
template <class M>
M ReadCheckedMessage(const rosbag::MessageInstance& m, const std::string& where,
                     void (*check)(const uint8_t*, size_t, const std::string&)) {
  if (!m.isType<M>()) {
    throw std::runtime_error(where + "message on " + m.getTopic() + " is not a " +
                             ros::message_traits::datatype<M>() + " (type " + m.getDataType() +
                             ", md5sum " + m.getMD5Sum() + ")");
  }
  // m.size() is the record's data length, which the bag structure check bounded by its chunk.
  std::vector<uint8_t> bytes(m.size());
  ros::serialization::OStream out(bytes.data(), static_cast<uint32_t>(bytes.size()));
  m.write(out);
  if (check) {
    check(bytes.data(), bytes.size(), where);
  }
  M msg;
  ros::serialization::IStream in(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::deserialize(in, msg);
  return msg;
}

}  // namespace ctlio::io
