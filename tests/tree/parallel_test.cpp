#include "tree/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace tightbvh {
namespace {

struct Counter {
  int calls = 0;
};

TEST(WorkerPool, RunsEveryIndexOnceWithTheWorkersScratch) {
  for (const unsigned threads : {1u, 2u, 3u, 8u}) {
    detail::WorkerPool<Counter> pool(threads);
    std::vector<std::atomic<int>> seen(100);
    std::atomic<int> calls{0};
    pool.run(seen.size(), [&](std::size_t i, Counter& scratch) {
      ++seen[i];
      ++scratch.calls;
      ++calls;
    });
    for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "threads " << threads << " index " << i;
    EXPECT_EQ(calls, 100);
  }
}

// Two failing indices; the higher one fails at once, the lower one only later (it sleeps
// first), so a pool that rethrew the first error caught would report the higher index.
// collide_batch and the builder rely on the lowest index winning, whatever the timing.
TEST(WorkerPool, RethrowsTheErrorOfTheLowestFailingIndex) {
  for (const unsigned threads : {2u, 3u, 4u}) {
    for (int round = 0; round < 3; ++round) {
      detail::WorkerPool<Counter> pool(threads);
      try {
        pool.run(40, [&](std::size_t i, Counter&) {
          if (i == 1) {
            std::this_thread::sleep_for(std::chrono::milliseconds(30));
            throw std::runtime_error("index 1");
          }
          if (i == 2) throw std::runtime_error("index 2");
        });
        ADD_FAILURE() << "no exception, threads " << threads;
      } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "index 1") << "threads " << threads << " round " << round;
      }
    }
  }
}

}  // namespace
}  // namespace tightbvh
