// PLY reader (PCL's parser, then ctlio's field conversion) on arbitrary bytes.
#include "ctlio/io/point_cloud_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("ply") / "in.ply";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  try {
    ctlio::io::ReadPly(path.string(), {0, false});
  } catch (const std::exception&) {
  }
  return 0;
}
