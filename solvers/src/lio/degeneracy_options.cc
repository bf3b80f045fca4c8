// The degeneracy options' checks, apart from the analysis (degeneracy.cc needs the window): the
// config parsers, and the YAML fuzz target that compiles only them, link this alone.
#include <stdexcept>
#include <string>

#include "ctlio/solvers/lio/degeneracy.h"

namespace ctlio::lio {

void DegeneracyOptions::Validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("OdometryConfig: ") + what);
  };
  require(translation_threshold >= 0 && translation_threshold < 3,
          "degeneracy.translation_threshold must be in [0, 3)");
  require(rotation_threshold >= 0 && rotation_threshold < 3,
          "degeneracy.rotation_threshold must be in [0, 3)");
  require(remap_information > 0, "degeneracy.remap_information must be positive");
}

}  // namespace ctlio::lio
