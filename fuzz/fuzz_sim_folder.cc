// ctlio simulator folder: input = ctlio_sim.yaml, imu.csv, scans.csv, scans/000000.bin,
// scans/000001.bin, ground_truth.csv, separated by "%%" lines.
#include "ctlio/io/sim_folder.h"
#include "dataset_fuzz.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto parts = ctlio::fuzz::SplitParts(data, size, 6);
  const auto dir = ctlio::fuzz::ScratchDir("sim_folder");
  const char* names[] = {"ctlio_sim.yaml",   "imu.csv",          "scans.csv",
                         "scans/000000.bin", "scans/000001.bin", "ground_truth.csv"};
  for (int i = 0; i < 6; ++i) ctlio::fuzz::WriteFile(dir / names[i], parts[i]);
  try {
    ctlio::io::SimFolderReader reader(dir.string());
    ctlio::fuzz::Drain(reader);
  } catch (const std::exception&) {
  }
  return 0;
}
