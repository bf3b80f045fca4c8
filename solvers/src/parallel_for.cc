#include "ctlio/solvers/parallel_for.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace ctlio::internal {
namespace {

// Where chunk c of `chunks` chunks of [0, n) begins (chunk c ends where c + 1 begins).
inline size_t ChunkBegin(size_t c, size_t n, size_t chunks) { return c * n / chunks; }

inline void CpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

// The process-wide helpers of ParallelFor. One loop at a time; a second caller meanwhile runs its
// chunks itself (RunOnPool).
//
// Chunks are claimed, not assigned: the caller and the helpers take the next unclaimed chunk until
// none is left, so a helper that is asleep, or not scheduled because the cores are busy, never
// holds the loop up — the caller then runs its chunks (which chunk runs where changes nothing:
// the chunks' bounds depend on n and their count only). The caller waits only for chunks a helper
// has claimed and is running.
class Pool {
 public:
  static Pool& Instance() {
    static Pool pool;
    return pool;
  }

  // false when another loop holds the pool (or the loop has more chunks than a ticket counts).
  bool TryRun(size_t chunks, size_t n, const std::function<void(size_t, size_t, size_t)>& f) {
    if (chunks > kMaxChunks) return false;
    std::unique_lock<std::mutex> run(run_mutex_, std::try_to_lock);
    if (!run.owns_lock()) return false;
    while (helpers_.size() + 1 < chunks) {
      try {
        helpers_.emplace_back([this] { HelperLoop(); });
      } catch (const std::system_error& e) {
        // Thread creation failed (a thread limit, no memory for a stack): an error that says so,
        // not an abort. The helpers started so far stay and serve later loops.
        throw std::runtime_error("ParallelFor: cannot start helper thread " +
                                 std::to_string(helpers_.size() + 1) + " of " +
                                 std::to_string(chunks - 1) + " (" + e.what() +
                                 "); ask for fewer threads (window.threads, "
                                 "lidar_frontend.threads)");
      }
    }
    task_ = &f;
    n_ = n;
    errors_.assign(chunks, nullptr);
    done_.store(0, std::memory_order_relaxed);
    {
      std::lock_guard<std::mutex> lock(wake_mutex_);
      if (++generation_ == 0) ++generation_;  // 0 stays "no loop yet" through the wrap-around
      // A new generation with no chunk claimed yet; publishes the fields above.
      ticket_.store(Ticket(generation_, chunks, 0), std::memory_order_release);
    }
    wake_.notify_all();
    RunChunks(generation_);
    // Chunks claimed by helpers are running: wait for them (short), yielding if it is not.
    for (int i = 0; done_.load(std::memory_order_acquire) != chunks; ++i) {
      if (i < 4096) {
        CpuRelax();
      } else {
        std::this_thread::yield();
      }
    }
    task_ = nullptr;
    for (const std::exception_ptr& e : errors_) {
      if (e) std::rethrow_exception(e);
    }
    return true;
  }

  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(wake_mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : helpers_) t.join();
  }

 private:
  Pool() = default;

  // The ticket word: the loop's generation (bits 32-63), its chunk count (16-31) and its next
  // unclaimed chunk (0-15). The count travels with the generation so that a helper holding a
  // ticket of a finished loop never compares it with the next loop's count: such a ticket has
  // every chunk claimed, and a claim succeeds only on the current word.
  static constexpr size_t kMaxChunks = 0xffff;
  static uint64_t Ticket(uint32_t generation, size_t chunks, size_t next) {
    return uint64_t{generation} << 32 | uint64_t{chunks} << 16 | uint64_t{next};
  }

  // Claims and runs the chunks of loop `generation` until none is left.
  void RunChunks(uint32_t generation) {
    for (;;) {
      uint64_t ticket = ticket_.load(std::memory_order_acquire);
      size_t c, chunks;
      do {
        if ((ticket >> 32) != generation) return;  // that loop is over
        chunks = static_cast<size_t>((ticket >> 16) & kMaxChunks);
        c = static_cast<size_t>(ticket & kMaxChunks);
        if (c >= chunks) return;
      } while (!ticket_.compare_exchange_weak(ticket, ticket + 1, std::memory_order_acq_rel,
                                              std::memory_order_acquire));
      // Claimed (the acquire sees the fields the loop published); they stay as they are until
      // every chunk is done.
      try {
        (*task_)(c, ChunkBegin(c, n_, chunks), ChunkBegin(c + 1, n_, chunks));
      } catch (...) {
        errors_[c] = std::current_exception();
      }
      done_.fetch_add(1, std::memory_order_acq_rel);
    }
  }

  void HelperLoop() {
    uint32_t seen = 0;
    while (WaitForLoop(&seen)) RunChunks(seen);
  }

  // Waits for a loop newer than *seen (polling for up to kSpinMicroseconds, then asleep) and sets
  // *seen to its generation; false when the pool stops.
  bool WaitForLoop(uint32_t* seen) {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::microseconds(kSpinMicroseconds);
    for (int i = 0;; ++i) {
      const auto generation = static_cast<uint32_t>(ticket_.load(std::memory_order_acquire) >> 32);
      if (generation != *seen) {
        *seen = generation;
        return true;
      }
      if ((i & 63) == 63 && Clock::now() > deadline) break;
      CpuRelax();
    }
    std::unique_lock<std::mutex> lock(wake_mutex_);
    wake_.wait(lock, [&] { return stop_ || generation_ != *seen; });
    *seen = generation_;
    return !stop_;
  }

  std::mutex run_mutex_;  // held by the loop on the pool
  std::vector<std::thread> helpers_;
  const std::function<void(size_t, size_t, size_t)>* task_ = nullptr;
  size_t n_ = 0;
  std::vector<std::exception_ptr> errors_;
  std::atomic<uint64_t> ticket_{0};  // Ticket(generation, chunks, next unclaimed chunk)
  std::atomic<size_t> done_{0};      // chunks of the current loop finished
  std::mutex wake_mutex_;            // guards generation_ and stop_
  std::condition_variable wake_;
  uint32_t generation_ = 0;
  bool stop_ = false;
  // ~ the gap between two evaluations of the solve (a linear solve), so the helper stays
  // polling through a solve and sleeps soon after it.
  static constexpr int kSpinMicroseconds = 300;
};

}  // namespace

void RunOnPool(size_t chunks, size_t n, const std::function<void(size_t, size_t, size_t)>& f) {
  if (Pool::Instance().TryRun(chunks, n, f)) return;
  for (size_t c = 0; c < chunks; ++c) f(c, ChunkBegin(c, n, chunks), ChunkBegin(c + 1, n, chunks));
}

}  // namespace ctlio::internal
