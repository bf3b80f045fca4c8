#include "lio/config_origin.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>

namespace ctlio::lioapp {

std::string DescribeConfig(const std::string& path) {
  if (path.empty()) {
    return "built-in defaults (no --config)";
  }
  std::string text = path;
  std::string file = path;
  // LoadOdometryYaml allows 8 files in a chain; the bound also stops a cycle here.
  for (int depth = 0; depth < 8; ++depth) {
    YAML::Node root;
    try {
      root = YAML::LoadFile(file);
    } catch (const std::exception&) {
      break;
    }
    const YAML::Node& read = root;  // a non-const operator[] would add the key
    if (!read.IsMap() || !read["base"] || !read["base"].IsScalar()) {
      break;
    }
    std::filesystem::path base(read["base"].Scalar());
    if (base.is_relative()) {
      base = std::filesystem::path(file).parent_path() / base;
    }
    file = base.lexically_normal().string();
    text += (depth == 0 ? " (extends " : ", which extends ") + file;
  }
  return file == path ? text : text + ")";
}

}  // namespace ctlio::lioapp
