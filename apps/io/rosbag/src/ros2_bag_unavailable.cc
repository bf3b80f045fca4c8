// Built instead of ros2_bag_containers.cc when the ROS 2 containers (ctlio::io_ros2) are not
// part of the build: ROS 2 bags are then not recognised, and reading or writing one says why.
#include <stdexcept>

#include "ctlio/io/bag_stream.h"
#include "ctlio/io/bag_writer.h"

namespace ctlio::io {

std::unique_ptr<BagStream> OpenRos2BagStream(const std::string& path) {
  throw std::runtime_error(path + ": ROS 2 bags cannot be read by this build (no ctlio::io_ros2)");
}

bool IsRos2BagPath(const std::string&) { return false; }

std::unique_ptr<Ros2ContainerWriter> OpenRos2ContainerWriter(const std::string& path,
                                                             ros2::Ros2Storage,
                                                             ros2::Ros2Compression) {
  throw std::runtime_error(path +
                           ": ROS 2 bags cannot be written by this build (no ctlio::io_ros2)");
}

}  // namespace ctlio::io
