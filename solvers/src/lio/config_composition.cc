#include "ctlio/solvers/lio/config_composition.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "ctlio/solvers/lio/odometry_config.h"
#include "ctlio/solvers/lio/yaml_io.h"

namespace ctlio::lio {

namespace {

constexpr int kMaxDepth = 8;
constexpr int kMaxFiles = 32;

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// `over`'s keys onto the mapping `base`: mappings key by key, anything else replaced. The nodes
// are shared, not copied, so that they keep their line numbers for error messages; a key new to
// `base` is inserted as its own node (operator[] would make a key node without a line).
void OverlayYaml(YAML::Node base, const YAML::Node& over) {
  for (const auto& kv : over) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& read = base;  // a non-const operator[] would add the key it looks up
    if (!read[key]) {
      base.force_insert(kv.first, kv.second);
      continue;
    }
    YAML::Node existing = base[key];
    if (existing.IsMap() && kv.second.IsMap()) {
      OverlayYaml(existing, kv.second);
    } else {
      base[key] = kv.second;
    }
  }
}

// The paths a file's `base:` names (one scalar or a list of scalars), relative to its folder.
std::vector<std::string> BasePaths(const std::string& path, const YAML::Node& base_key) {
  const std::string where = YamlWhere(path, base_key.Mark()) + ": base: ";
  std::vector<YAML::Node> names;
  if (base_key.IsSequence() && base_key.size() > 0) {
    for (const YAML::Node& n : base_key) names.push_back(n);
  } else {
    names.push_back(base_key);
  }
  std::vector<std::string> paths;
  for (const YAML::Node& n : names) {
    if (!n.IsScalar() || n.Scalar().empty()) {
      throw std::runtime_error(where +
                               "must be the path of the config this one extends, or a list of "
                               "paths");
    }
    std::filesystem::path p(n.Scalar());
    if (p.is_relative()) p = std::filesystem::path(path).parent_path() / p;
    paths.push_back(p.lexically_normal().string());
  }
  return paths;
}

class Composer {
 public:
  explicit Composer(std::vector<ComposedFile>* files) : files_(files) {}

  // The files of `paths` overlaid in order, each prefix checked under its last file's name.
  YAML::Node ComposeList(const std::vector<std::string>& paths, const std::string& base_of,
                         int depth) {
    YAML::Node merged(YAML::NodeType::Map);
    for (const std::string& path : paths) {
      const YAML::Node file = LoadWithBases(path, base_of, depth);
      if (!file.IsDefined() || file.IsNull()) continue;  // an empty file sets nothing
      if (!file.IsMap()) throw std::runtime_error(path + ": the config must be a YAML mapping");
      OverlayYaml(merged, file);
      OdometryConfigFromYaml(merged, path);
    }
    return merged;
  }

 private:
  // One file with its bases applied under it (the bases checked; the file itself is checked by
  // the caller, as the end of its prefix).
  YAML::Node LoadWithBases(const std::string& path, const std::string& base_of, int depth) {
    if (++count_ > kMaxFiles) {
      throw std::runtime_error(path + ": more than " + std::to_string(kMaxFiles) +
                               " files in one config");
    }
    YAML::Node root = LoadYamlFile(path, "odometry config");
    const YAML::Node& read = root;  // a non-const operator[] would add the key it looks up
    if (!read.IsMap() || !read["base"]) {
      if (files_ != nullptr) files_->push_back({path, base_of});
      return root;
    }
    const YAML::Node base_key = read["base"];
    const std::string where = YamlWhere(path, base_key.Mark()) + ": base: ";
    const std::vector<std::string> bases = BasePaths(path, base_key);
    if (depth + 1 >= kMaxDepth) {
      throw std::runtime_error(where + "more than " + std::to_string(kMaxDepth) +
                               " files extend each other (a cycle?)");
    }
    // A device or a folder named as the base would block or fail obscurely in the parser.
    for (const std::string& b : bases) {
      std::error_code error;
      if (std::filesystem::exists(b, error) && !std::filesystem::is_regular_file(b, error)) {
        throw std::runtime_error(where + b + " is not a regular file");
      }
    }
    YAML::Node merged;
    try {
      merged = ComposeList(bases, path, depth + 1);
    } catch (const std::exception& e) {
      throw std::runtime_error(where + e.what());
    }
    root.remove("base");
    OverlayYaml(merged, root);
    if (files_ != nullptr) files_->push_back({path, base_of});
    return merged;
  }

  std::vector<ComposedFile>* files_;
  int count_ = 0;
};

}  // namespace

std::vector<std::string> SplitConfigList(const std::string& spec) {
  std::error_code error;
  if (spec.find(',') == std::string::npos || std::filesystem::is_regular_file(spec, error)) {
    return {spec};
  }
  std::vector<std::string> paths;
  size_t begin = 0;
  while (true) {
    const size_t end = spec.find(',', begin);
    const std::string name = Trim(spec.substr(begin, end == std::string::npos ? end : end - begin));
    if (name.empty()) {
      throw std::runtime_error("config list '" + spec +
                               "': an empty file name (files are separated by single commas)");
    }
    paths.push_back(name);
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return paths;
}

YAML::Node ComposeOdometryYaml(const std::vector<std::string>& paths,
                               std::vector<ComposedFile>* files) {
  if (paths.empty()) throw std::runtime_error("no odometry config file given");
  Composer composer(files);
  return composer.ComposeList(paths, "", 0);
}

}  // namespace ctlio::lio
