#pragma once
// Internal: all_pairs' answer put in order (sorted by (a, b), duplicates dropped), as QueryResult
// promises. A deep overlap reports thousands of pairs a query, and std::sort's comparisons on
// them are branches the predictor misses about one time in five (a fifth of an overlap query's
// mispredictions, callgrind); a least-significant-digit radix sort on the packed (a, b) keys has
// no data-dependent branch.
#include <vector>

#include "tightbvh/collide.hpp"

namespace tightbvh::query_detail {

/// Sorts `pairs` by (a, b) and removes repeated pairs.
void sort_unique_pairs(std::vector<TrianglePair>& pairs);

}  // namespace tightbvh::query_detail
