// Which configuration a run uses, said at its start: every file of the --config composition in
// the order applied (the files of the list, each after the files its `base:` names;
// config_composition.h), or that no file was given and the built-in defaults apply.
#pragma once

#include <string>

namespace ctlio::lioapp {

// "data/a.yaml" for one file without a base; else every file in the order applied, a base
// marked as such, e.g. "data/b.yaml (base of data/a.yaml), data/a.yaml, cal.yaml; later files win
// key by key". An empty spec: "built-in defaults (no --config)". Call it after the config loaded,
// which reports any error of the files (a config that does not load is described as given).
std::string DescribeConfig(const std::string& spec);

}  // namespace ctlio::lioapp
