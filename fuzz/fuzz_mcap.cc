// MCAP reader (apps/io/ros2) on arbitrary bytes: a single .mcap opened as a ROS 2 bag and drained
// with every topic, then with the first topic only (the chunk-skipping path of the indexes).
// Seeds: ctlio's MCAP writer (none/zstd/lz4 chunks, without summary, without chunks).
#include "ctlio/io/ros2_bag.h"
#include "fuzz_common.h"

namespace {

void Drain(const std::string& path, bool filter) {
  ctlio::io::ros2::Ros2BagReader reader(path);
  if (filter && !reader.topics().empty()) reader.SetTopicFilter({0});
  ctlio::io::ros2::Ros2Message m;
  while (reader.Next(&m)) {
    if (m.topic >= reader.topics().size()) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("mcap") / "in.mcap";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  for (const bool filter : {false, true}) {
    try {
      Drain(path.string(), filter);
    } catch (const std::exception&) {
    }
  }
  return 0;
}
