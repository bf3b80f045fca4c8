// An empty scratch folder per test, named after the test and the process so that ctest -j and two
// build trees running at once never share one.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace ctlio::testing {

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("ctlio_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace ctlio::testing
