// KITTI folder: input = times.txt, velodyne/000000.bin, velodyne/000001.bin,
// velodyne_times/000001.bin, poses.txt, calib.txt, separated by "%%" lines (scan 0 has no time
// file: its times come from the azimuth).
#include "ctlio/io/kitti.h"
#include "dataset_fuzz.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto parts = ctlio::fuzz::SplitParts(data, size, 6);
  const auto dir = ctlio::fuzz::ScratchDir("kitti_folder");
  const char* names[] = {"times.txt",           "velodyne/000000.bin",
                         "velodyne/000001.bin", "velodyne_times/000001.bin",
                         "poses.txt",           "calib.txt"};
  for (int i = 0; i < 6; ++i) ctlio::fuzz::WriteFile(dir / names[i], parts[i]);
  try {
    ctlio::io::KittiReader reader(dir.string());
    ctlio::fuzz::Drain(reader);
  } catch (const std::exception&) {
  }
  return 0;
}
