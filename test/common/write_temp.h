// A small text file in gtest's temp folder, for the tests of readers and config loaders that
// feed them hand-written files; returns its path.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace ctlio::testing {

inline std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace ctlio::testing
