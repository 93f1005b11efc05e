#pragma once
// A minimal fork-join helper for the builder, refit and collide_batch (TBB is not a dependency),
// on up to `threads` std::jthreads, each with its own long-lived scratch buffers. The results must
// not depend on which worker ran what.
// - run(count, fn) calls fn(i, scratch) for i in [0, count). When calls throw, the exception of
//   the lowest failing index is rethrown: every lower index was claimed before it and still runs
//   to the end, whatever the timing.
// - run_tasks(first, before, fn) runs a task and every task it spawns (fn(task, scratch, spawn)),
//   always the waiting task that comes first in `before` (a strict total order): no barrier
//   anywhere, a worker only waits when nothing is queued. A task that throws spawns nothing and
//   the rest still runs, so the set of failed tasks does not depend on the timing; the exception
//   of the first of them in `before` is rethrown.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <optional>
#include <queue>
#include <thread>
#include <utility>
#include <vector>

namespace tightbvh::detail {

template <class Scratch>
class WorkerPool {
 public:
  explicit WorkerPool(unsigned threads) : scratch_(std::max(1u, threads)) {}

  template <class Fn>
  void run(std::size_t count, Fn&& fn) {
    const std::size_t workers = std::min<std::size_t>(scratch_.size(), count);
    if (workers <= 1) {
      for (std::size_t i = 0; i < count; ++i) fn(i, scratch_[0]);
      return;
    }
    std::atomic<std::size_t> next{0};
    std::atomic<bool> failed{false};
    std::mutex mutex;
    std::size_t error_index = count;
    std::exception_ptr error;
    {
      std::vector<std::jthread> pool;
      pool.reserve(workers);
      for (std::size_t w = 0; w < workers; ++w) {
        pool.emplace_back([&, w] {
          for (std::size_t i; !failed.load(std::memory_order_relaxed) && (i = next.fetch_add(1)) < count;) {
            try {
              fn(i, scratch_[w]);
            } catch (...) {
              const std::lock_guard lock(mutex);
              if (i < error_index) error_index = i, error = std::current_exception();
              failed = true;
            }
          }
        });
      }
    }  // joins
    if (error) std::rethrow_exception(error);
  }

  template <class Task, class Before, class Fn>
  void run_tasks(const Task& first, Before before, Fn&& fn) {
    // std::priority_queue pops its largest element: invert `before` so top() is the first task.
    const auto later = [&](const Task& a, const Task& b) { return before(b, a); };
    std::priority_queue<Task, std::vector<Task>, decltype(later)> queue(later);
    queue.push(first);
    std::mutex mutex;
    std::condition_variable wake;
    std::size_t running = 0;
    std::optional<std::pair<Task, std::exception_ptr>> error;
    const auto work = [&](Scratch& scratch) {
      std::vector<Task> spawned;
      std::unique_lock lock(mutex);
      for (;;) {
        wake.wait(lock, [&] { return !queue.empty() || running == 0; });
        if (queue.empty()) return;  // nothing queued and nothing running that could spawn
        const Task task = queue.top();
        queue.pop();
        ++running;
        lock.unlock();
        spawned.clear();
        std::exception_ptr failure;
        try {
          fn(task, scratch, [&](const Task& child) { spawned.push_back(child); });
        } catch (...) {
          failure = std::current_exception();
          spawned.clear();
        }
        lock.lock();
        if (failure && (!error || before(task, error->first))) error.emplace(task, failure);
        for (const Task& child : spawned) queue.push(child);
        --running;
        wake.notify_all();
      }
    };
    if (scratch_.size() <= 1) {
      work(scratch_[0]);
    } else {
      std::vector<std::jthread> pool;
      pool.reserve(scratch_.size());
      for (Scratch& scratch : scratch_) pool.emplace_back([&] { work(scratch); });
    }  // joins
    if (error) std::rethrow_exception(error->second);
  }

 private:
  std::vector<Scratch> scratch_;
};

}  // namespace tightbvh::detail
