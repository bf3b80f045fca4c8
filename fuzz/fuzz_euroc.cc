// The EuRoC IMU CSV and vicon2gt ground-truth readers (apps/io euroc.h) on arbitrary bytes.
#include "ctlio/io/euroc.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("euroc") / "data.csv";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  try {
    ctlio::io::ReadEurocImuCsv(path.string());
  } catch (const std::exception&) {
  }
  try {
    ctlio::io::ReadVicon2gtCsv(path.string());
  } catch (const std::exception&) {
  }
  return 0;
}
