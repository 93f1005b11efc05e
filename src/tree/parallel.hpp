#pragma once
// A minimal fork-join helper for the builder and collide_batch (TBB is not a dependency):
// run(count, fn) calls fn(i, scratch) for i in [0, count) on up to `threads` std::jthreads, each
// with its own long-lived scratch buffers. The results must not depend on which worker ran which
// index. When calls throw, the exception of the lowest failing index is rethrown: every lower
// index was claimed before it and still runs to the end, whatever the timing.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
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

 private:
  std::vector<Scratch> scratch_;
};

}  // namespace tightbvh::detail
