// Livox's own point-cloud message in ROS 2 bags, `livox_ros_driver2/msg/CustomMsg` (the struct of
// livox_msgs.h), in CDR (cdr.h).
// Errors as cdr_messages.h's: "<where>corrupt livox_ros_driver2/msg/CustomMsg message: <what>".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/io/cdr.h"
#include "ctlio/io/livox_msgs.h"

namespace ctlio::io::ros2 {

void DecodeCdr(const uint8_t* data, size_t size, const std::string& where, livox::CustomMsg* msg);
std::vector<uint8_t> EncodeCdr(const livox::CustomMsg& msg, CdrEndian endian = CdrEndian::kLittle);

}  // namespace ctlio::io::ros2
