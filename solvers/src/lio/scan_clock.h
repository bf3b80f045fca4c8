// What the single-pass pipeline (lio_odometry.cc) and the warm-up replay driver
// (calibrating_odometry.cc) both report per scan: the calling thread's CPU time, wall time, and
// notes appended to a ScanResult's message. Internal to the solvers library.
#pragma once

#include <chrono>
#include <ctime>
#include <string>

#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio::internal {

// CPU time of the calling thread [ms]: the per-scan cost without other threads' work or waits.
inline double ThreadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// Wall time since t0 [ms].
inline double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Appends a note to the scan's message ("; "-separated).
inline void AddNote(ScanResult* result, const std::string& note) {
  result->message += (result->message.empty() ? "" : "; ") + note;
}

}  // namespace ctlio::lio::internal
