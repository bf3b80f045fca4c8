// Rate limit of repeated reader warnings: the first few of each kind from one file (or bag topic)
// are logged in full, with their line or message number; the rest are only counted, and
// LogTotals() says how many there were. 10⁶ duplicate IMU stamps in a CSV used to print 10⁶
// warning lines (hundreds of MB of log) that buried everything else. Header-only, so that every
// reader (apps/io and apps/io/rosbag) uses it without a new source file.
#pragma once

#include <glog/logging.h>

#include <cstddef>
#include <map>
#include <string>
#include <utility>

namespace ctlio::io {

class WarningLimiter {
 public:
  // Warnings shown in full per kind: enough to see the pattern (every other line, one block).
  static constexpr size_t kDefaultShown = 5;

  explicit WarningLimiter(std::string source, size_t shown = kDefaultShown)
      : source_(std::move(source)), shown_(shown) {}

  // Counts one warning of `kind`; true when it is among the first `shown` of its kind (log it).
  bool Count(const std::string& kind) { return ++counts_[kind] <= shown_; }

  size_t count(const std::string& kind) const {
    const auto it = counts_.find(kind);
    return it == counts_.end() ? 0 : it->second;
  }

  // Of each kind with more warnings than were shown: "<source>: N <kind> warnings in all (the
  // first K logged)". Once; a second call logs nothing new.
  void LogTotals() {
    for (auto& [kind, n] : counts_) {
      if (n > shown_ && reported_[kind] != n) {
        LOG(WARNING) << source_ << ": " << n << " " << kind << " warnings in all (the first "
                     << shown_ << " logged)";
        reported_[kind] = n;
      }
    }
  }

 private:
  std::string source_;
  size_t shown_;
  std::map<std::string, size_t> counts_, reported_;
};

}  // namespace ctlio::io
