// Expects `f()` to throw a std::runtime_error whose message contains every one of `parts` (file
// names, line numbers, the field or flag at fault): bad input must be named, not just rejected.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace ctlio::testing {

template <typename F>
void ExpectError(F f, const std::vector<std::string>& parts) {
  try {
    f();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    for (const auto& p : parts) EXPECT_THAT(e.what(), ::testing::HasSubstr(p));
  }
}

}  // namespace ctlio::testing
