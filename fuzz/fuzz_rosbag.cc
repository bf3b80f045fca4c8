// ROS 1 bag reader (RosbagSource, apps/io/rosbag) on arbitrary bytes: opened with and without a
// preset, drained as the odometry drains it. The bag library underneath (Debian's librosbag) is not
// instrumented; ctlio validates the bag's record structure before handing it the file
// (rosbag_check.h), so that a corrupt length or count is a clear error, not a crash or a huge
// allocation inside the library.
#include "ctlio/io/rosbag_source.h"
#include "dataset_fuzz.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("rosbag") / "in.bag";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  try {
    ctlio::io::RosbagOptions options;
    options.max_imu_gap_ns = size % 2 ? 100'000'000 : 0;
    ctlio::io::RosbagSource source(path.string(), options);
    source.ImuFromLidar();
    ctlio::fuzz::Drain(source);
  } catch (const std::exception&) {
  }
  return 0;
}
