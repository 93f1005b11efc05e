#include "pair_sort.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstddef>

namespace tightbvh::query_detail {

void sort_unique_pairs(std::vector<TrianglePair>& pairs) {
  // Below this the comparison sort is as fast and needs no heap buffers.
  constexpr std::size_t kRadixFrom = 256;
  const std::size_t n = pairs.size();
  if (n < 2) return;
  if (n < kRadixFrom) {  // the comparison sort on 64-bit keys: one branch a comparison, not two
    std::array<std::uint64_t, kRadixFrom> keys;
    for (std::size_t i = 0; i < n; ++i) keys[i] = std::uint64_t{pairs[i].a} << 32 | pairs[i].b;
    const auto last = keys.begin() + static_cast<std::ptrdiff_t>(n);
    std::sort(keys.begin(), last);
    const auto end = static_cast<std::size_t>(std::unique(keys.begin(), last) - keys.begin());
    for (std::size_t i = 0; i < end; ++i)
      pairs[i] = {static_cast<std::uint32_t>(keys[i] >> 32), static_cast<std::uint32_t>(keys[i])};
    pairs.resize(end);
    return;
  }
  if (n > 0xFFFFFFFFu) {  // beyond the counters' range
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return;
  }
  // Keys (a << bits_b) | b use only the bits the indices need, so that a mesh of thousands of
  // triangles sorts in three passes of 11 bits, not six of 64.
  std::uint32_t any_a = 0, any_b = 0;
  for (const TrianglePair& p : pairs) {
    any_a |= p.a;
    any_b |= p.b;
  }
  const int bits_b = std::bit_width(any_b);
  const int bits = std::bit_width(any_a) + bits_b;
  std::vector<std::uint64_t> keys(n), spare(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = std::uint64_t{pairs[i].a} << bits_b | pairs[i].b;
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::array<std::uint32_t, kBuckets> count{};
    for (const std::uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
    if (count[(keys[0] >> shift) & (kBuckets - 1)] == n) continue;  // one digit for all: in order
    std::uint32_t start = 0;
    for (std::uint32_t& c : count) {
      const std::uint32_t here = c;
      c = start;
      start += here;
    }
    for (const std::uint64_t k : keys) spare[count[(k >> shift) & (kBuckets - 1)]++] = k;
    keys.swap(spare);
  }
  // Back to pairs, each repeat written over (the index moves only past a new key).
  const std::uint64_t mask_b = (std::uint64_t{1} << bits_b) - 1;
  std::size_t out = 0;
  std::uint64_t previous = ~keys[0];
  for (const std::uint64_t k : keys) {
    pairs[out] = {static_cast<std::uint32_t>(k >> bits_b), static_cast<std::uint32_t>(k & mask_b)};
    out += k != previous;
    previous = k;
  }
  pairs.resize(out);
}

}  // namespace tightbvh::query_detail
