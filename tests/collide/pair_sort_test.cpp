// all_pairs' answer in order (src/collide/pair_sort.hpp): the radix sort must give std::sort's
// order with repeats dropped, for every size around its switch from the comparison sort, index
// ranges from a few bits to the full 32 (one digit pass to six), many repeats, and keys that share
// their low digits (the passes it skips).
#include "collide/pair_sort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace tightbvh {
namespace {

std::vector<TrianglePair> reference(std::vector<TrianglePair> pairs) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

void expect_sorted_like_std(const std::vector<TrianglePair>& input) {
  std::vector<TrianglePair> sorted = input;
  query_detail::sort_unique_pairs(sorted);
  const std::vector<TrianglePair> expected = reference(input);
  ASSERT_EQ(sorted.size(), expected.size());
  EXPECT_TRUE(std::equal(sorted.begin(), sorted.end(), expected.begin()));
}

TEST(PairSort, MatchesStdSortOnRandomPairs) {
  std::mt19937 rng(38);
  for (const std::uint32_t range_a : {1u, 7u, 1000u, 70000u, 0xFFFFFFFFu})
    for (const std::uint32_t range_b : {1u, 2u, 6400u, 1u << 20, 0xFFFFFFFFu})
      for (const std::size_t n : {0u, 1u, 255u, 256u, 257u, 3000u, 20000u}) {
        std::uniform_int_distribution<std::uint32_t> a(0, range_a - 1), b(0, range_b - 1);
        std::vector<TrianglePair> pairs(n);
        for (TrianglePair& p : pairs) p = {a(rng), b(rng)};
        SCOPED_TRACE(testing::Message() << "range_a " << range_a << " range_b " << range_b << " n " << n);
        expect_sorted_like_std(pairs);
      }
}

TEST(PairSort, DropsRepeatsAndKeepsExtremes) {
  std::vector<TrianglePair> pairs;
  for (int r = 0; r < 5; ++r)
    for (std::uint32_t i = 0; i < 400; ++i) pairs.push_back({i % 17, 0xFFFFFFFFu - i % 3});
  pairs.push_back({0xFFFFFFFFu, 0});
  pairs.push_back({0, 0});
  expect_sorted_like_std(pairs);
  std::vector<TrianglePair> same(1000, TrianglePair{5, 9});
  query_detail::sort_unique_pairs(same);
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0], (TrianglePair{5, 9}));
}

TEST(PairSort, KeysSharingLowDigits) {
  // Every b a multiple of 2^12: the first 11-bit pass sees one digit and is skipped.
  std::mt19937 rng(7);
  std::vector<TrianglePair> pairs(5000);
  for (TrianglePair& p : pairs)
    p = {static_cast<std::uint32_t>(rng() % 300), static_cast<std::uint32_t>(rng() % 64) << 12};
  expect_sorted_like_std(pairs);
}

}  // namespace
}  // namespace tightbvh
