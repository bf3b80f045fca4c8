// Shared helpers of the libFuzzer targets (docs/developer-guide/fuzzing.md): every
// target writes the fuzzer's bytes into files of a per-process scratch folder and runs one reader
// on them. A reader may throw std::exception (a clear error); anything else — a crash, a
// sanitizer report, another exception type, a hang — is a finding.
#pragma once

#include <glog/logging.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace ctlio::fuzz {

// The scratch folder of this process (emptied on first use, removed at exit).
inline const std::filesystem::path& ScratchDir(const std::string& target) {
  struct Folder {
    std::filesystem::path path;
    ~Folder() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Folder dir = [&] {
    // In memory where available: a folder target writes up to six files per input.
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                           ? std::filesystem::path("/dev/shm")
                                           : std::filesystem::temp_directory_path();
    Folder f{base / ("ctlio_fuzz_" + target + "_" + std::to_string(::getpid()))};
    std::filesystem::remove_all(f.path);
    std::filesystem::create_directories(f.path);
    return f;
  }();
  return dir.path;
}

inline void WriteFile(const std::filesystem::path& p, const std::string& bytes) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
}

// Several files in one input: parts separated by the line "%%" (the seed corpus uses the same
// separator, so the fuzzer mutates each file and the split alike).
inline std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t parts) {
  const std::string all(reinterpret_cast<const char*>(data), size);
  const std::string sep = "\n%%\n";
  std::vector<std::string> out;
  size_t pos = 0;
  while (out.size() + 1 < parts) {
    const size_t at = all.find(sep, pos);
    if (at == std::string::npos) break;
    out.push_back(all.substr(pos, at - pos));
    pos = at + sep.size();
  }
  out.push_back(all.substr(pos));
  out.resize(parts);
  return out;
}

// Readers log warnings for every recovery: keep the fuzzer's output to its findings.
inline void QuietLogging() {
  FLAGS_minloglevel = 3;
  FLAGS_logtostderr = true;
}

}  // namespace ctlio::fuzz
