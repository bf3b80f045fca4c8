// Odometry YAML configs (data/*.yaml): the odometry's keys and the run's `input:` section.
#include <yaml-cpp/yaml.h>

#include "ctlio/solvers/lio/input_checks.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    YAML::Node root = YAML::Load(std::string(reinterpret_cast<const char*>(data), size));
    const ctlio::lio::InputCheckOptions checks =
        ctlio::lio::TakeInputCheckOptions(&root, "in.yaml");
    checks.Validate();
    ctlio::lio::OdometryConfigFromYaml(root, "in.yaml").Validate();
  } catch (const std::exception&) {
  }
  return 0;
}
