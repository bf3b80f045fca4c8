// KITTI-style .bin scan plus its float32 time file: input = scan bytes, "%%" line, time bytes.
#include "ctlio/io/point_cloud_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto parts = ctlio::fuzz::SplitParts(data, size, 2);
  const auto dir = ctlio::fuzz::ScratchDir("kitti_bin");
  ctlio::fuzz::WriteFile(dir / "scan.bin", parts[0]);
  ctlio::fuzz::WriteFile(dir / "times.bin", parts[1]);
  for (const int floats : {3, 4}) {
    for (const char* times : {"", "times.bin"}) {
      try {
        ctlio::io::ReadKittiBin((dir / "scan.bin").string(), floats,
                                *times ? (dir / times).string() : "", 1000);
      } catch (const std::exception&) {
      }
    }
  }
  return 0;
}
