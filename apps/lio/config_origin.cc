#include "lio/config_origin.h"

#include <yaml-cpp/yaml.h>

#include <exception>
#include <vector>

#include "ctlio/solvers/lio/config_composition.h"

namespace ctlio::lioapp {

std::string DescribeConfig(const std::string& spec) {
  if (spec.empty()) {
    return "built-in defaults (no --config)";
  }
  std::vector<lio::ComposedFile> files;
  try {
    lio::ComposeOdometryYaml(lio::SplitConfigList(spec), &files);
  } catch (const std::exception&) {
    return spec;
  }
  if (files.size() == 1) {
    return files.front().path;
  }
  std::string text;
  for (const lio::ComposedFile& f : files) {
    text += (text.empty() ? "" : ", ") + f.path;
    if (!f.base_of.empty()) {
      text += " (base of " + f.base_of + ")";
    }
  }
  return text + "; later files win key by key";
}

}  // namespace ctlio::lioapp
