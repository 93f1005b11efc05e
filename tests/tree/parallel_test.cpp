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

// A task is a range [begin, end); it spawns its two halves until they hold one element.
struct Range {
  int begin;
  int end;
};
bool bigger_first(const Range& a, const Range& b) {
  return a.end - a.begin != b.end - b.begin ? a.end - a.begin > b.end - b.begin : a.begin < b.begin;
}

TEST(WorkerPool, RunTasksRunsEverySpawnedTaskOnce) {
  for (const unsigned threads : {1u, 2u, 3u, 8u}) {
    detail::WorkerPool<Counter> pool(threads);
    std::vector<std::atomic<int>> leaves(1000);
    std::atomic<int> tasks{0};
    pool.run_tasks(Range{0, 1000}, bigger_first, [&](const Range& r, Counter& scratch, auto spawn) {
      ++tasks;
      ++scratch.calls;
      if (r.end - r.begin == 1) {
        ++leaves[r.begin];
        return;
      }
      const int mid = (r.begin + r.end) / 2;
      spawn(Range{r.begin, mid});
      spawn(Range{mid, r.end});
    });
    for (std::size_t i = 0; i < leaves.size(); ++i) EXPECT_EQ(leaves[i], 1) << "threads " << threads << " leaf " << i;
    EXPECT_EQ(tasks, 1999) << "threads " << threads;  // a full binary tree over 1000 leaves
  }
}

// One worker runs the waiting tasks strictly in `before` order: here, bigger ranges first.
TEST(WorkerPool, RunTasksTakesTheFirstWaitingTask) {
  detail::WorkerPool<Counter> pool(1);
  std::vector<int> sizes;
  pool.run_tasks(Range{0, 7}, bigger_first, [&](const Range& r, Counter&, auto spawn) {
    sizes.push_back(r.end - r.begin);
    if (r.end - r.begin == 1) return;
    const int mid = r.begin + 1;  // unbalanced: 1 and the rest
    spawn(Range{r.begin, mid});
    spawn(Range{mid, r.end});
  });
  EXPECT_EQ(sizes, (std::vector<int>{7, 6, 5, 4, 3, 2, 1, 1, 1, 1, 1, 1, 1}));
}

// Two tasks fail: [3, 4) at once, [1, 2) only later (it sleeps first). The error rethrown is
// that of the first failed task in `before` order (same size, lower begin), whatever the timing,
// and the other tasks still run (the set of failures must not depend on the timing).
TEST(WorkerPool, RunTasksRethrowsTheFirstFailedTaskInOrder) {
  for (const unsigned threads : {1u, 2u, 3u}) {
    for (int round = 0; round < 3; ++round) {
      detail::WorkerPool<Counter> pool(threads);
      std::atomic<int> leaves{0};
      try {
        pool.run_tasks(Range{0, 8}, bigger_first, [&](const Range& r, Counter&, auto spawn) {
          if (r.end - r.begin == 1) {
            ++leaves;
            if (r.begin == 1) {
              std::this_thread::sleep_for(std::chrono::milliseconds(30));
              throw std::runtime_error("task 1");
            }
            if (r.begin == 3) throw std::runtime_error("task 3");
            return;
          }
          const int mid = (r.begin + r.end) / 2;
          spawn(Range{r.begin, mid});
          spawn(Range{mid, r.end});
        });
        ADD_FAILURE() << "no exception, threads " << threads;
      } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "task 1") << "threads " << threads << " round " << round;
      }
      EXPECT_EQ(leaves, 8) << "threads " << threads;
    }
  }
}

}  // namespace
}  // namespace tightbvh
