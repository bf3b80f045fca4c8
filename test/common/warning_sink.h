// Collects the WARNING lines glog writes while it is installed, for tests of the readers' and the
// pipeline's warnings (the message text only, without glog's prefix).
#pragma once

#include <glog/logging.h>

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

namespace ctlio::testing {

class WarningSink : public google::LogSink {
 public:
  WarningSink() { google::AddLogSink(this); }
  ~WarningSink() override { google::RemoveLogSink(this); }
  WarningSink(const WarningSink&) = delete;
  WarningSink& operator=(const WarningSink&) = delete;

  void send(google::LogSeverity severity, const char* /*full_filename*/,
            const char* /*base_filename*/, int /*line*/, const struct ::tm* /*time*/,
            const char* message, size_t length) override {
    if (severity != google::GLOG_WARNING) {
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    lines_.emplace_back(message, length);
  }
  std::vector<std::string> lines() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lines_;
  }
  // Every line, each followed by a newline.
  std::string text() {
    std::string all;
    for (const std::string& l : lines()) {
      all += l + "\n";
    }
    return all;
  }
  size_t CountContaining(const std::string& needle) {
    size_t n = 0;
    for (const std::string& l : lines()) {
      n += l.find(needle) != std::string::npos ? 1 : 0;
    }
    return n;
  }
  bool Has(const std::string& needle) { return CountContaining(needle) > 0; }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

}  // namespace ctlio::testing
