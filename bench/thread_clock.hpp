#pragma once
// CPU time of the calling thread, for the benchmark programs: the machine is shared, and wall-
// clock time would charge other processes' load to whatever is being measured. Everything timed
// with it is single-threaded.
#include <time.h>

namespace tightbvh::bench_support {

[[nodiscard]] inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace tightbvh::bench_support
