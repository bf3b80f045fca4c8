#include "ctlio/io/checked_output.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace ctlio::io {
namespace {
std::string Reason() { return errno != 0 ? std::strerror(errno) : "stream error"; }
}  // namespace

std::ofstream OpenForWriting(const std::string& path, std::ios::openmode mode) {
  errno = 0;
  std::ofstream out(path, mode);
  if (!out) throw std::runtime_error(path + ": cannot open for writing (" + Reason() + ")");
  return out;
}

void CloseChecked(std::ofstream& out, const std::string& path) {
  errno = 0;
  if (out.is_open()) {
    out.flush();
    const bool ok = static_cast<bool>(out);
    out.close();
    if (ok && !out.fail()) return;
  }
  throw std::runtime_error(path + ": write failed (" + Reason() + ")");
}

void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out = OpenForWriting(path);
  out << text;
  CloseChecked(out, path);
}

}  // namespace ctlio::io
