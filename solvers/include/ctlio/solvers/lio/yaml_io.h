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

// Upper bounds of the config's count keys, shared by the loaders (with the key's line) and the
// Validate functions (for library users): a thread count far above any machine's cores (thread
// creation fails long before 65536 helpers), voxel and neighbour counts far above any use (each
// point of a query scans them). Range errors name the key and the range.
inline constexpr int kMaxConfigThreads = 256;
inline constexpr int kMaxPointsPerVoxel = 10'000;
inline constexpr int kMaxNeighbours = 1'000;
inline constexpr int kMaxWindowKnots = 1'000;

// A key handler like SetFromYaml that also requires lo <= value <= hi: the error names the file,
// the line, the key (`key`, as the user wrote it in its section) and the allowed range.
template <typename T>
YamlSetter SetInRange(T* field, T lo, T hi, const std::string& source, const std::string& key) {
  return [=](const YAML::Node& value) {
    const T v = value.as<T>();
    if (!(lo <= v && v <= hi)) {
      throw std::runtime_error(YamlWhere(source, value.Mark()) + ": " + key + " = " +
                               value.Scalar() + " is out of range: must be in [" +
                               std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    *field = v;
  };
}

}  // namespace ctlio::lio
