// The files a program run wrote, each with what it holds, listed at the end of the run so that a
// user knows where to look. Every writer registers its file right where it writes it (one line:
// `files.Add(path, "what it is")`), so that a new output is listed without touching the listing.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace ctlio::lioapp {

class OutputFiles {
 public:
  struct Entry {
    std::string path;
    std::string description;
  };

  // Registers `path` (written, or about to be) with a short description; a path registered again
  // keeps its first place and takes the new description.
  void Add(const std::string& path, const std::string& description);

  // "Files written:" and one line per file, in the order registered: the path, padded to the
  // longest, then the description. Nothing when no file was registered.
  void Print(std::ostream& os) const;

  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;
};

}  // namespace ctlio::lioapp
