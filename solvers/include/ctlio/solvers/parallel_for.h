// Splits [0, n) into `threads` contiguous, nearly equal chunks and runs f(chunk, begin, end) on
// each, chunk 0 on the calling thread and the others on threads started for the call (a few tens
// of microseconds, against the milliseconds of the front-end loops it serves). The chunks depend
// on n and `threads` only, so a caller that writes chunk c's results to its own slots, or merges
// the chunks in order, gets the same answer for any number of threads.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace ctlio {

template <typename F>
void ParallelFor(int threads, size_t n, F&& f) {
  const size_t chunks =
      std::max<size_t>(1, std::min<size_t>(static_cast<size_t>(std::max(threads, 1)), n));
  const auto begin_of = [&](size_t c) { return c * n / chunks; };
  if (chunks == 1) {
    f(size_t{0}, size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(chunks);
  std::vector<std::thread> workers;
  workers.reserve(chunks - 1);
  for (size_t c = 1; c < chunks; ++c) {
    workers.emplace_back([&, c] {
      try {
        f(c, begin_of(c), begin_of(c + 1));
      } catch (...) {
        errors[c] = std::current_exception();
      }
    });
  }
  try {
    f(size_t{0}, size_t{0}, begin_of(1));
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace ctlio
