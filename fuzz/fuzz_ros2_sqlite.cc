// rosbag2's SQLite 3 storage (apps/io/ros2) on arbitrary bytes: the input is written to a .db3
// file, opened as a ROS 2 bag through the sqlite3 library and drained. Seeds: ctlio's SQLite bag
// writer.
#include "ctlio/io/ros2_bag.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("ros2_sqlite") / "in.db3";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  try {
    ctlio::io::ros2::Ros2BagReader reader(path.string());
    ctlio::io::ros2::Ros2Message m;
    while (reader.Next(&m)) {
      if (m.topic >= reader.topics().size()) __builtin_trap();
    }
  } catch (const std::exception&) {
  }
  return 0;
}
