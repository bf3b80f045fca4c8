// Where the tests find the project's files and the shared real recordings. The two paths are
// compiled into one small library (test_paths.cc) instead of onto every test's command line, so
// that no test object depends on where the checkout is: a compiler cache then serves every clone
// and worktree of the project.
#pragma once

#include <string>

namespace ctlio::testing {

// The project's source folder (data/, tools/ below it).
std::string SourceDir();

// The shared real recordings (CMake cache variable CTLIO_SHARED_DATA_DIR, default
// ../shared/data beside the project); the tests that read them skip when it is absent.
std::string SharedDataDir();

}  // namespace ctlio::testing
