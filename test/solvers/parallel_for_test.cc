// ParallelFor (solvers/parallel_for.h): every index runs exactly once, in chunks whose bounds
// depend on n and the thread count only, whichever thread claims them; a chunk's exception reaches
// the caller; a loop started while the pool is busy (from another thread, or from inside a chunk)
// runs on its caller with the same chunks instead of waiting.
#include "ctlio/solvers/parallel_for.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace ctlio {
namespace {

// chunk c of n over t threads: [c·n/k, (c+1)·n/k) with k = min(t, n) chunks.
void ExpectChunks(int threads, size_t n) {
  const size_t k = std::max<size_t>(1, std::min<size_t>(static_cast<size_t>(threads), n));
  std::vector<std::atomic<int>> hits(n);
  std::vector<std::pair<size_t, size_t>> bounds(k, {n + 1, n + 1});
  ParallelFor(threads, n, [&](size_t c, size_t begin, size_t end) {
    bounds[c] = {begin, end};
    for (size_t i = begin; i < end; ++i) hits[i].fetch_add(1);
  });
  for (size_t c = 0; c < k && n > 0; ++c) {
    EXPECT_EQ(bounds[c].first, c * n / k) << threads << " threads, n " << n << ", chunk " << c;
    EXPECT_EQ(bounds[c].second, (c + 1) * n / k);
  }
  for (size_t i = 0; i < n; ++i) EXPECT_EQ(hits[i].load(), 1) << "index " << i;
}

TEST(ParallelFor, EveryIndexOnceInFixedChunks) {
  for (const int threads : {1, 2, 3, 4}) {
    for (const size_t n : {size_t{0}, size_t{1}, size_t{2}, size_t{5}, size_t{1000}}) {
      ExpectChunks(threads, n);
    }
  }
}

// Thousands of short loops back to back (the solve's pattern: a loop per evaluation) neither lose
// nor repeat a chunk, whether the helpers are polling or asleep between them.
TEST(ParallelFor, ManyShortLoops) {
  std::vector<int> sums;
  for (int loop = 0; loop < 5000; ++loop) {
    std::vector<int> part(2, 0);
    ParallelFor(2, 100, [&](size_t c, size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) part[c] += static_cast<int>(i);
    });
    ASSERT_EQ(part[0] + part[1], 4950) << "loop " << loop;
    ASSERT_EQ(part[0], 1225);
    if (loop % 1000 == 999) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// Loops whose chunk counts change from one to the next (1, 4, 2, 3, ...): a helper still holding
// the previous loop's ticket must not claim a chunk of the next one, which would run that chunk
// twice (or return before a chunk ended). What ThreadSanitizer caught once under load, before the
// chunk count travelled in the ticket with the generation.
TEST(ParallelFor, LoopsOfChangingChunkCountsRunEachChunkOnce) {
  constexpr int kCounts[] = {1, 4, 2, 3, 1, 3, 4, 2};
  for (int loop = 0; loop < 20000; ++loop) {
    const int threads = kCounts[loop % 8];
    std::vector<int> runs(static_cast<size_t>(threads), 0);
    ParallelFor(threads, 8, [&](size_t c, size_t, size_t) { ++runs[c]; });
    for (int c = 0; c < threads; ++c) {
      ASSERT_EQ(runs[static_cast<size_t>(c)], 1) << "loop " << loop << ", chunk " << c;
    }
  }
}

TEST(ParallelFor, ExceptionOfAnyChunkReachesTheCaller) {
  for (const size_t bad : {size_t{0}, size_t{1}, size_t{2}}) {
    EXPECT_THROW(ParallelFor(3, 30,
                             [&](size_t c, size_t, size_t) {
                               if (c == bad) throw std::runtime_error("chunk failed");
                             }),
                 std::runtime_error)
        << "chunk " << bad;
  }
  ExpectChunks(3, 30);  // the pool still works afterwards
}

TEST(ParallelFor, NestedAndConcurrentLoopsRunOnTheirCallers) {
  std::atomic<int> inner{0};
  ParallelFor(2, 2, [&](size_t, size_t, size_t) {
    ParallelFor(2, 10, [&](size_t, size_t begin, size_t end) {
      inner.fetch_add(static_cast<int>(end - begin));
    });
  });
  EXPECT_EQ(inner.load(), 20);
  std::vector<long> totals(4, 0);
  std::vector<std::thread> callers;
  for (int t = 0; t < 4; ++t) {
    callers.emplace_back([&, t] {
      for (int loop = 0; loop < 500; ++loop) {
        std::vector<long> part(2, 0);
        ParallelFor(2, 1000, [&](size_t c, size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) part[c] += static_cast<long>(i);
        });
        totals[t] += part[0] + part[1];
      }
    });
  }
  for (std::thread& c : callers) c.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(totals[t], 500L * 499500L) << "caller " << t;
}

// Thread creation that fails (here: an address-space limit leaves no room for the helpers' stacks)
// is a std::runtime_error naming the cause and the config keys, not an abort from an uncaught
// std::system_error. In a child process, whose limit does not touch the other tests.
[[noreturn]] void LoopUnderAnAddressSpaceLimit() {
  size_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const rlim_t now = rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE));
  const rlimit limit{now + (16u << 20), now + (16u << 20)};  // 16 MB: two 8 MB stacks at most
  setrlimit(RLIMIT_AS, &limit);
  try {
    ParallelFor(4000, 4000, [](size_t, size_t, size_t) {});
    std::fprintf(stderr, "no error\n");
    _exit(1);
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    _exit(3);
  }
}

TEST(ParallelFor, FailingThreadCreationIsAClearError) {
  // A fresh process: the pool's helpers of the earlier tests are not forked along.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(LoopUnderAnAddressSpaceLimit(), ::testing::ExitedWithCode(3),
              "ParallelFor: cannot start helper thread [0-9]+ of 3999 .*window.threads, "
              "lidar_frontend.threads");
}

}  // namespace
}  // namespace ctlio
