// Progress of a long run on a stream. On a terminal one status line is rewritten in place ('\r');
// on anything else (stderr redirected to a file or a pipe) the '\r' updates would pile up into one
// line of tens of kB, so there a status line is written, newline-terminated, only every
// `interval_s` of wall time or when the count crosses another tenth of the total, and at the end.
#pragma once

#include <chrono>
#include <functional>
#include <ostream>
#include <string>

namespace ctlio::lioapp {

class ProgressReporter {
 public:
  // Wall-clock seconds since some fixed origin (replaceable in tests).
  using Clock = std::function<double()>;

  ProgressReporter(std::ostream& os, bool terminal, double interval_s = 5.0, Clock clock = {});

  // True if the file descriptor is a terminal (isatty).
  static bool IsTerminal(int fd);

  // The status after `done` of `total` items (total 0: unknown), `text` one line without newline.
  void Update(size_t done, size_t total, const std::string& text);

  // A line of its own (a warning about one item): ends a status line left open on a terminal.
  // After `max_events` (SetEventLimit) the events are only counted.
  void Event(const std::string& text);

  // Shows at most `max_events` events; Finish then says how many more there were and `where` to
  // find them (a run with a degenerate scan in every other scan would otherwise print hundreds).
  void SetEventLimit(size_t max_events, const std::string& where);

  // The last status, if not shown yet (non-terminal), the end of the line (terminal), and how many
  // events were not shown.
  void Finish();

 private:
  void EndOpenLine();

  std::ostream& os_;
  bool terminal_;
  double interval_s_;
  Clock clock_;
  double last_print_s_ = 0.0;
  int last_tenth_ = 0;
  bool line_open_ = false;  // terminal: a '\r' line without its newline yet
  std::string pending_;     // non-terminal: the newest status not yet written
  size_t max_events_ = static_cast<size_t>(-1);
  size_t events_ = 0;
  std::string events_where_;
};

}  // namespace ctlio::lioapp
