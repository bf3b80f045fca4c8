#include "lio/progress.h"

#include <unistd.h>

#include <utility>

namespace ctlio::lioapp {

ProgressReporter::ProgressReporter(std::ostream& os, bool terminal, double interval_s, Clock clock)
    : os_(os), terminal_(terminal), interval_s_(interval_s), clock_(std::move(clock)) {
  if (!clock_) {
    const auto origin = std::chrono::steady_clock::now();
    clock_ = [origin] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - origin).count();
    };
  }
  last_print_s_ = clock_();
}

bool ProgressReporter::IsTerminal(int fd) { return isatty(fd) == 1; }

void ProgressReporter::Update(size_t done, size_t total, const std::string& text) {
  if (terminal_) {
    // Trailing spaces clear the rest of a longer previous line.
    os_ << '\r' << text << "   " << std::flush;
    line_open_ = true;
    return;
  }
  const double now = clock_();
  const int tenth = total > 0 ? static_cast<int>(10 * done / total) : 0;
  if (now - last_print_s_ >= interval_s_ || tenth > last_tenth_ || (total > 0 && done >= total)) {
    os_ << text << '\n' << std::flush;
    last_print_s_ = now;
    last_tenth_ = tenth;
    pending_.clear();
  } else {
    pending_ = text;
  }
}

void ProgressReporter::Event(const std::string& text) {
  if (events_++ >= max_events_) {
    return;
  }
  EndOpenLine();
  os_ << text << '\n' << std::flush;
}

void ProgressReporter::SetEventLimit(size_t max_events, const std::string& where) {
  max_events_ = max_events;
  events_where_ = where;
}

void ProgressReporter::Finish() {
  EndOpenLine();
  if (!pending_.empty()) {
    os_ << pending_ << '\n';
  }
  pending_.clear();
  if (events_ > max_events_) {
    os_ << "  (" << events_ - max_events_ << " more such lines not shown"
        << (events_where_.empty() ? "" : "; " + events_where_) << ")\n";
  }
  events_ = 0;
  os_ << std::flush;
}

void ProgressReporter::EndOpenLine() {
  if (line_open_) {
    os_ << '\n';
  }
  line_open_ = false;
}

}  // namespace ctlio::lioapp
