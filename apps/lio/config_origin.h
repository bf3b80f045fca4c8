// Which configuration a run uses, said at its start: the --config file with the files it extends
// (`base:` chains, LoadOdometryYaml), or that no file was given and the built-in defaults apply.
#pragma once

#include <string>

namespace ctlio::lioapp {

// "data/a.yaml" or "data/a.yaml (extends data/b.yaml, which extends data/c.yaml)"; an empty path:
// "built-in defaults (no --config)". Reads only the `base:` keys (call it after the config
// loaded, which reports any error of the files; here a file that cannot be read ends the chain).
std::string DescribeConfig(const std::string& path);

}  // namespace ctlio::lioapp
