// Rate limit of repeated reader warnings: the first few of each kind from one file (or bag topic)
// are logged in full, with their line or message number; the rest are only counted, and
// LogTotals() says how many there were. 10⁶ duplicate IMU stamps in a CSV used to print 10⁶
// warning lines (hundreds of MB of log) that buried everything else. Header-only, so that every
// reader (apps/io and apps/io/rosbag) uses it without a new source file.
#pragma once

#include <glog/logging.h>

#include <atomic>
#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ctlio::io {

// One kind of recovered input defect of a run: how many times a reader recovered from it and
// where the first one was. Readers hand these on (DataSource::InputDefects) so that a run that
// exits 0 after recoveries says so in evaluation.txt, not only in a log nobody keeps.
struct InputDefect {
  std::string kind;  // "duplicate IMU time", "points outside the scan interval", ...
  size_t count = 0;
  std::string first;  // where the first one was: file and line, bag message, the reader's text
};

class WarningLimiter {
 public:
  // Warnings shown in full per kind: enough to see the pattern (every other line, one block).
  static constexpr size_t kDefaultShown = 5;

  explicit WarningLimiter(std::string source, size_t shown = kDefaultShown)
      : source_(std::move(source)), shown_(shown) {}

  // Strict input (ctlio_odometry --strict; library users: SetStrict): every recovery a reader
  // applies is a defect the user asked not to have guessed around, so the first warning of any
  // kind throws instead, naming the source and the defect. Process-wide, because a reader's
  // limiters are created inside its constructor and its calls (CheckImuStream makes its own).
  static void SetStrict(bool strict) { StrictFlag().store(strict); }
  static bool Strict() { return StrictFlag().load(); }

  // Counts one warning of `kind`; true when it is among the first `shown` of its kind (log it).
  // In strict mode it throws instead: `<detail>: <kind> (--strict: …)`, the detail being where the
  // defect is (file and line, bag message, the reader's own message), by default the source.
  bool Count(const std::string& kind, const std::string& detail = {}) {
    if (Strict()) {
      throw std::runtime_error((detail.empty() ? source_ : detail) + ": " + kind +
                               " (--strict: a defect that would be recovered "
                               "is an error; run without it to recover and log)");
    }
    if (!first_.count(kind)) first_[kind] = detail.empty() ? source_ : detail;
    return ++counts_[kind] <= shown_;
  }

  // Every kind counted so far, in kind order.
  std::vector<InputDefect> Defects() const {
    std::vector<InputDefect> out;
    for (const auto& [kind, n] : counts_) out.push_back({kind, n, first_.at(kind)});
    return out;
  }

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
  static std::atomic<bool>& StrictFlag() {
    static std::atomic<bool> strict{false};
    return strict;
  }

  std::string source_;
  size_t shown_;
  std::map<std::string, size_t> counts_, reported_;
  std::map<std::string, std::string> first_;
};

}  // namespace ctlio::io
