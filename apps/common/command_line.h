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

#include <ostream>
#include <string>
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

}  // namespace ctlio::apps
