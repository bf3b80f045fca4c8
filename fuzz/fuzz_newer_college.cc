// Newer College 2020 folder: input = ouster_imu/data.csv, registered_poses.csv and two scans
// (cloud_1583836591_182590000.pcd, cloud_1583836591_282590000.pcd), separated by "%%" lines.
#include "ctlio/io/newer_college.h"
#include "dataset_fuzz.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto parts = ctlio::fuzz::SplitParts(data, size, 4);
  const auto dir = ctlio::fuzz::ScratchDir("newer_college");
  const auto scans = dir / "raw_format" / "ouster_zip_files" / "ouster_scan";
  ctlio::fuzz::WriteFile(dir / "raw_format" / "ouster_imu" / "data.csv", parts[0]);
  ctlio::fuzz::WriteFile(dir / "ground_truth" / "registered_poses.csv", parts[1]);
  ctlio::fuzz::WriteFile(scans / "cloud_1583836591_182590000.pcd", parts[2]);
  ctlio::fuzz::WriteFile(scans / "cloud_1583836591_282590000.pcd", parts[3]);
  try {
    ctlio::io::NewerCollegeOptions options;
    options.max_imu_gap_error_ns = size % 2 ? 100'000'000 : 0;
    ctlio::io::NewerCollegeReader reader(dir.string(), options);
    ctlio::fuzz::Drain(reader);
  } catch (const std::exception&) {
  }
  return 0;
}
