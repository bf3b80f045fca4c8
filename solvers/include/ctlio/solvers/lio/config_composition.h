// Odometry configs composed of several files: `--config a.yaml,b.yaml` on the command line and
// `base:` inside a file (one path or a list). Later files win key by key: a key inside a section
// replaces that key only, a value or a list replaces the whole value. So an overlay without a
// `base:` (data/calibration.yaml) works on top of any config.
#pragma once

#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace ctlio::lio {

// One file of a composition, in the order the files are applied (a file's bases before it).
struct ComposedFile {
  std::string path;     // as named (a base: relative to the folder of the file naming it)
  std::string base_of;  // the file whose `base:` names it; empty for a file of the list
};

// "a.yaml,b.yaml" → {"a.yaml", "b.yaml"} (spaces around a name trimmed). A spec that is itself an
// existing regular file stays one name (a file name with a comma). An empty name in the list
// (e.g. "a.yaml,,b.yaml") throws std::runtime_error naming the spec.
std::vector<std::string> SplitConfigList(const std::string& spec);

// Reads the files of `paths` (each with its `base:` files first) and overlays them in order.
// Every prefix of the composition is converted and checked (OdometryConfigFromYaml) under the
// name of the file that ends it, so an error names the file and line of the offending key in
// whichever file it is (a bad combination of values, which has no line, names the file that
// completed it). Errors of a base are prefixed with the `base:` line that names it. At most 8
// files deep (a cycle is reported as too deep) and 32 files in all; a base must be a regular
// file. `files` (optional) receives every file read, in the order applied. The result has no
// `base` key.
YAML::Node ComposeOdometryYaml(const std::vector<std::string>& paths,
                               std::vector<ComposedFile>* files = nullptr);

}  // namespace ctlio::lio
