// An empty scratch folder per test, named after the test and the process so that ctest -j and two
// build trees running at once never share one. Removed when the test process exits (each run
// left ~20 MB in the temp folder before); set CTLIO_KEEP_TEST_DIRS=1 to keep them for a look.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace ctlio::testing {

namespace internal {

// The folders FreshTempDir made in this process; removed by the destructor at exit.
class TempDirRegistry {
 public:
  ~TempDirRegistry() {
    if (std::getenv("CTLIO_KEEP_TEST_DIRS") != nullptr) {
      return;
    }
    for (const std::filesystem::path& d : dirs_) {
      std::error_code ignored;
      std::filesystem::remove_all(d, ignored);
    }
  }
  void Add(const std::filesystem::path& d) {
    for (const std::filesystem::path& known : dirs_) {
      if (known == d) {
        return;
      }
    }
    dirs_.push_back(d);
  }

 private:
  std::vector<std::filesystem::path> dirs_;
};

inline TempDirRegistry& Registry() {
  static TempDirRegistry registry;
  return registry;
}

}  // namespace internal

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("ctlio_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  internal::Registry().Add(d);
  return d;
}

}  // namespace ctlio::testing
