#include "common/test_paths.h"

namespace ctlio::testing {

std::string SourceDir() { return CTLIO_SOURCE_DIR; }

std::string SharedDataDir() { return CTLIO_SHARED_DATA_DIR; }

}  // namespace ctlio::testing
