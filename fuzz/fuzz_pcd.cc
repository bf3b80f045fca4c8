// PCD reader (ctlio's own, apps/io/src/pcd_reader.cc) on arbitrary bytes, with and without a
// required time field.
#include "ctlio/io/point_cloud_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("pcd") / "in.pcd";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  for (const bool require_time : {false, true}) {
    try {
      ctlio::io::ReadPcd(path.string(), {1583836591000000000LL, require_time});
    } catch (const std::exception&) {
    }
  }
  return 0;
}
