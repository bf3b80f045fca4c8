// ParallelFor splits [0, n) into `threads` contiguous, nearly equal chunks and runs
// f(chunk, begin, end) on each: chunk 0 on the calling thread, the others on the persistent
// helper threads of one process-wide pool. The chunks depend on n and `threads` only, so a caller
// that writes chunk c's results to its own slots, or merges the chunks in order, gets the same
// answer for any number of threads — and when the pool is busy with another caller's loop the
// chunks simply run one after the other on the calling thread, with that same answer.
//
// Why a persistent pool that spins: the solve hands work to the second core a few dozen times per
// scan (every evaluation's interpolations and lidar rows, docs/experiments/latency.md), each worth
// ~0.1 ms. Starting a thread per call costs tens of microseconds, and so does waking a sleeping one
// on a virtual machine; a helper that keeps polling for a while after its last chunk picks the next
// one up in about a microsecond. It polls for ~0.3 ms (parallel_for.cc), then sleeps.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>

namespace ctlio {

namespace internal {
// Runs f over `chunks` chunks of [0, n) (chunks ≥ 2) on the pool, chunk 0 on the caller.
void RunOnPool(size_t chunks, size_t n, const std::function<void(size_t, size_t, size_t)>& f);
}  // namespace internal

template <typename F>
void ParallelFor(int threads, size_t n, F&& f) {
  const size_t chunks =
      std::max<size_t>(1, std::min<size_t>(static_cast<size_t>(std::max(threads, 1)), n));
  if (chunks == 1) {
    f(size_t{0}, size_t{0}, n);
    return;
  }
  internal::RunOnPool(chunks, n, std::function<void(size_t, size_t, size_t)>(std::ref(f)));
}

}  // namespace ctlio
