// Odometry YAML configs (data/*.yaml): every section, the `input:` gates and `per_method:`
// included.
#include <yaml-cpp/yaml.h>

#include "ctlio/solvers/lio/odometry_config.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const YAML::Node root = YAML::Load(std::string(reinterpret_cast<const char*>(data), size));
    ctlio::lio::OdometryConfigFromYaml(root, "in.yaml").Validate();
  } catch (const std::exception&) {
  }
  return 0;
}
