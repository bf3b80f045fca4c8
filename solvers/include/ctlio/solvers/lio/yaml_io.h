// YAML helpers shared by every ctlio config loader: errors name the file and line.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <stdexcept>
#include <string>

namespace ctlio::lio {

// "<source>:<line>" (1-based) or just "<source>" when the mark has no line.
inline std::string YamlWhere(const std::string& source, const YAML::Mark& mark) {
  return mark.line >= 0 ? source + ":" + std::to_string(mark.line + 1) : source;
}

// Loads a YAML file; a missing file or a syntax error becomes a runtime_error that names the
// file (and line), with `what` saying what the file was supposed to hold.
inline YAML::Node LoadYamlFile(const std::string& path, const std::string& what) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(path + ": cannot open " + what);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(YamlWhere(path, e.mark) + ": " + e.msg);
  }
}

// A key handler that assigns the node's value to `field`.
using YamlSetter = std::function<void(const YAML::Node&)>;
template <typename T>
YamlSetter SetFromYaml(T* field) {
  return [field](const YAML::Node& value) { *field = value.as<T>(); };
}

}  // namespace ctlio::lio
