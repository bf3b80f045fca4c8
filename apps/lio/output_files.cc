#include "lio/output_files.h"

#include <algorithm>

namespace ctlio::lioapp {

void OutputFiles::Add(const std::string& path, const std::string& description) {
  for (Entry& e : entries_) {
    if (e.path == path) {
      e.description = description;
      return;
    }
  }
  entries_.push_back({path, description});
}

void OutputFiles::Print(std::ostream& os) const {
  if (entries_.empty()) {
    return;
  }
  size_t width = 0;
  for (const Entry& e : entries_) {
    width = std::max(width, e.path.size());
  }
  os << "Files written:\n";
  for (const Entry& e : entries_) {
    os << "  " << e.path << std::string(width - e.path.size(), ' ') << "  " << e.description
       << '\n';
  }
}

}  // namespace ctlio::lioapp
