// Built instead of ros2_bag_reader_stream.cc when the ROS 2 containers (ctlio::io_ros2) are not
// part of the build: ROS 2 bags are then not recognised, and opening one says why.
#include <stdexcept>

#include "ctlio/io/bag_stream.h"

namespace ctlio::io {

std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path) {
  throw std::runtime_error(path + ": ROS 2 bags cannot be read by this build (no ctlio::io_ros2)");
}

bool IsRos2BagPath(const std::string&) { return false; }

}  // namespace ctlio::io
