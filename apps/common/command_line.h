// The command line of every ctlio program: gflags parsing with a help that shows the program's own
// flags only.
//
// gflags' --help lists every flag linked into the binary (≈100 of glog and gflags before the
// program's own) and exits 1; its --helpshort keeps the flags of a file named like the program,
// which none of ours is ("No modules matched"). Here:
//   --help, --helpshort  the usage text, then the program's own flags (type, default, meaning);
//                        exit 0
//   --helpfull           gflags' full list, the logging and gflags flags included; exit 0
//   --helpon, --helpmatch, --helpxml, --version, ...: gflags' handling
//   an unknown flag      gflags' "ERROR: unknown command line flag 'x'"; exit 1
#pragma once

#include <gflags/gflags.h>

#include <cmath>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace ctlio::apps {

// Parses and removes the flags of *argc/*argv (what remains are the positional arguments) with
// `usage` as the help's first part: its first line names the program and says what it does, the
// next lines give a typical command. Handles the help flags above (printing to stdout and exiting).
void ParseCommandLine(int* argc, char*** argv, const char* usage);

// The flags that belong to the program: every flag not defined by gflags or glog themselves,
// whether in the program's file, a header it includes or a library of the project. (The flag's
// file name cannot tell: with ccache's base_dir, __FILE__ is a path relative to the build folder.)
std::vector<gflags::CommandLineFlagInfo> OwnFlags();

// The help of `flags`: one "--name=default  (type)" line each, the description wrapped below it at
// 100 columns.
void PrintFlags(const std::vector<gflags::CommandLineFlagInfo>& flags, std::ostream& os);

// The items of a comma-separated flag value ("singer_lio,imu_input"), empty items skipped.
std::vector<std::string> SplitList(const std::string& s);

// The largest thread count a flag or config key may ask for (window.threads and
// lidar_frontend.threads have the same bound): far above the cores of any machine the programs run
// on, far below the threads a process may create.
inline constexpr int kMaxThreads = 256;

// The start-up check of a count or rate flag: throws std::invalid_argument
// "--<name>=<value> is out of range: must be in [lo, hi]<note>" unless lo <= value <= hi (NaN is
// never in range). Programs call it for every count and rate flag before any work, so that a
// huge --threads is an error naming the flag, not an abort inside thread creation, and a rate of
// 1e300 Hz never sizes an allocation.
template <typename T>
void RequireInRange(const char* name, T value, T lo, T hi, const char* note = "") {
  static_assert(std::is_arithmetic_v<T>, "a count or a rate");
  if (lo <= value && value <= hi) {
    return;  // false for NaN
  }
  std::ostringstream m;
  m.precision(10);
  m << "--" << name << '=' << value << " is out of range: must be in [" << lo << ", " << hi << ']'
    << note;
  throw std::invalid_argument(m.str());
}

}  // namespace ctlio::apps
