// Trajectory files (TUM, KITTI poses with an optional times file): input = trajectory bytes,
// "%%" line, times bytes.
#include "ctlio/io/trajectory_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto parts = ctlio::fuzz::SplitParts(data, size, 2);
  const auto dir = ctlio::fuzz::ScratchDir("trajectory");
  const std::string traj = (dir / "traj.txt").string(), times = (dir / "times.txt").string();
  ctlio::fuzz::WriteFile(traj, parts[0]);
  ctlio::fuzz::WriteFile(times, parts[1]);
  try {
    ctlio::io::ReadTrajectory(traj);
  } catch (const std::exception&) {
  }
  try {
    ctlio::io::ReadKittiPoses(traj, times);
  } catch (const std::exception&) {
  }
  try {
    ctlio::io::ReadTum(traj);
  } catch (const std::exception&) {
  }
  return 0;
}
