#include "common/command_line.h"

#include <cstdlib>
#include <iostream>
#include <set>
#include <sstream>

namespace ctlio::apps {
namespace {

// One flag of every source file of gflags and glog that defines flags (gflags.cc,
// gflags_reporting.cc, gflags_completions.cc; glog's logging.cc, vlog_is_on.cc, utilities.cc, or
// flags.cc in glog ≥ 0.7): a flag is foreign iff it comes from the file of one of these.
constexpr const char* kForeignProbes[] = {
    "flagfile", "help",      "tab_completion_columns", "logtostderr", "minloglevel",
    "v",        "vmodule",   "symbolize_stacktrace",   "log_dir",     "stderrthreshold",
    "fromenv",  "helpmatch", "tab_completion_word",    "logbuflevel", "max_log_size"};

bool BoolFlag(const char* name) {
  std::string value;
  return gflags::GetCommandLineOption(name, &value) && value == "true";
}

std::string ProgramName(const char* argv0) {
  const std::string path = argv0 == nullptr ? "" : argv0;
  return path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
}

// `text` wrapped at `width` columns after `indent` spaces (a word longer than a line stays whole).
void Wrapped(const std::string& text, size_t indent, size_t width, std::ostream& os) {
  std::istringstream words(text);
  size_t column = 0;
  for (std::string w; words >> w;) {
    if (column > indent && column + 1 + w.size() > width) {
      os << '\n';
      column = 0;
    }
    if (column == 0) {
      os << std::string(indent, ' ') << w;
      column = indent + w.size();
    } else {
      os << ' ' << w;
      column += 1 + w.size();
    }
  }
  if (column > 0) {
    os << '\n';
  }
}

}  // namespace

std::vector<gflags::CommandLineFlagInfo> OwnFlags() {
  std::set<std::string> foreign;
  for (const char* name : kForeignProbes) {
    gflags::CommandLineFlagInfo info;
    if (gflags::GetCommandLineFlagInfo(name, &info)) {
      foreign.insert(info.filename);
    }
  }
  std::vector<gflags::CommandLineFlagInfo> all, own;
  gflags::GetAllFlags(&all);  // sorted by file, then name
  for (const gflags::CommandLineFlagInfo& f : all) {
    if (foreign.count(f.filename) == 0) {
      own.push_back(f);
    }
  }
  return own;
}

void PrintFlags(const std::vector<gflags::CommandLineFlagInfo>& flags, std::ostream& os) {
  for (const gflags::CommandLineFlagInfo& f : flags) {
    const std::string value = f.type == "string" ? "\"" + f.default_value + "\"" : f.default_value;
    os << "  --" << f.name << '=' << value << "  (" << f.type << ")\n";
    Wrapped(f.description, 6, 100, os);
  }
}

std::vector<std::string> SplitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) {
      out.push_back(item);
    }
  }
  return out;
}

void ParseCommandLine(int* argc, char*** argv, const char* usage) {
  gflags::SetUsageMessage(usage);
  const std::string program = ProgramName(*argc > 0 ? (*argv)[0] : nullptr);
  // Unknown flags and bad values end the program here (gflags' message, exit 1).
  gflags::ParseCommandLineNonHelpFlags(argc, argv, true);
  if (BoolFlag("help") || BoolFlag("helpshort")) {
    std::cout << usage << "\n\nFlags of " << program
              << " (--helpfull also lists the logging and gflags flags):\n";
    PrintFlags(OwnFlags(), std::cout);
    std::cout.flush();
    std::exit(0);
  }
  if (BoolFlag("helpfull")) {
    gflags::ShowUsageWithFlags((*argv)[0]);
    std::exit(0);
  }
  gflags::HandleCommandLineHelpFlags();
}

}  // namespace ctlio::apps
