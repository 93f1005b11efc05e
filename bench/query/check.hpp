#pragma once
// Checking an engine's answers against the reference pairs, pose by pose.
#include <vector>

#include "bench.hpp"

namespace tightbvh::bench {

struct Agreement {
  int yes_no = 0;              // poses whose yes/no differs from the reference (not near-touching)
  int yes_no_near = 0;         // ... where the reference pairs all touch within the tolerance
  int pair_sets = 0;           // poses whose pair set differs beyond near-touching pairs
  long missing = 0, extra = 0; // pairs missing / extra, not near-touching
  long near_missing = 0, near_extra = 0;  // differing pairs within tolerance of touching
  double max_extra_distance = 0;           // farthest extra pair (e.g. contact margins)
  int distances = 0;                       // distance mode: poses beyond the tolerance
  double max_distance_error = 0;           // distance mode: largest |d - reference|

  [[nodiscard]] long mismatches() const { return yes_no + missing + extra + distances; }
  [[nodiscard]] long near_touching() const { return yes_no_near + near_missing + near_extra; }
};

// `tolerance` is absolute (1e-9 x mesh scale): a differing pair counts as near-touching when
// moving B's triangle by `tolerance` can change whether the two triangles touch.
[[nodiscard]] Agreement compare(const Input& in, Mode mode, const Answers& got,
                                const std::vector<std::vector<Pair>>& reference,
                                const std::vector<Pose>& poses, double tolerance);

// Distance mode: an answer agrees when |d - reference| <= 1e-9 reference + 1e-12 scale.
[[nodiscard]] Agreement compare_distances(const Answers& got, const std::vector<double>& reference, double scale);

// Margin mode: the pair sets must be equal (the same predicate on the same triangles).
[[nodiscard]] Agreement compare_exact_pairs(const Answers& got, const std::vector<std::vector<Pair>>& reference);

// Solid mode: the yes/no of every pose must equal the reference's (exact predicates on both sides).
[[nodiscard]] Agreement compare_hits(const Answers& got, const std::vector<std::uint8_t>& reference);

// Distance between triangle ta of A and triangle tb of B placed at `pose` (0 if they touch).
[[nodiscard]] double triangle_distance(const Input& in, const Pose& pose, Pair pair);

}  // namespace tightbvh::bench
