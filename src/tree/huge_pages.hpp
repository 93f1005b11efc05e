#pragma once
// The builder writes about 210 bytes of fresh memory per triangle (corners 72, nodes 136). With
// 4 KiB pages each page is one fault, and on a virtual machine a fault costs far more than the
// writes: 23 ms for the 7 MB node array of a 52k-triangle mesh on the 2-core VM of
// docs/benchmarks.md ("Machine"), a tenth of a one-thread `auto` build, and all of it before a
// second thread can help (docs/design-notes/tree-builder.md, "Threads: one queue, largest first,
// no barrier").
// Transparent huge pages cut that to a few faults; the kernel may ignore the hint.
#include <cstddef>
#include <cstdint>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tightbvh::detail {

// Reserves room for `count` elements of an empty vector and asks for huge pages on the whole
// 2 MiB pages of it, before anything has touched them.
template <class T>
void reserve_huge_pages(std::vector<T>& v, std::size_t count) {
  v.reserve(count);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (begin + count * sizeof(T)) & ~(kHuge - 1);
  if (last > first) (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
}

}  // namespace tightbvh::detail
