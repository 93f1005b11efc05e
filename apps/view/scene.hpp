#pragma once
// The data of a view page as JSON for its script (page.html): meshes, boxes per tree level,
// volumes, contacts. Coordinates go out rounded to 1e-5 of the power of ten of the scene's size
// (axes to 1e-5): enough to draw, and half the text of full doubles.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <span>
#include <string>

#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/distance.hpp"
#include "view/decimate.hpp"

namespace tightbvh::view {

// Beyond this many boxes in the levels up to the selected one, deeper levels are left out of the
// page (their volumes are still listed).
inline constexpr std::size_t kMaxDrawnBoxes = 8'000;
// The descent picture of `tightbvh collide --view` shows at most this many visited node pairs
// (the first ones in visiting order; every pair is still counted per level).
inline constexpr std::size_t kMaxDrawnPairs = 3'000;

// {"triangles", "drawn_triangles", "decimated", "max_drawn_triangles", "positions" (x y z per
// vertex, after `pose`), "indices" (3 per drawn triangle)}.
[[nodiscard]] nlohmann::json mesh_json(const Mesh& mesh, const Pose& pose = {},
                                       std::size_t max_triangles = kMaxDrawnTriangles);

// 15 numbers: center, the three axes (columns of Obb::axes), half extents (rounded as above, to
// the box's own size).
[[nodiscard]] nlohmann::json box_json(const Obb& box);

// One fitter's tree: {"fitter", "seconds", "sum_volume", "volume_per_level", "boxes_per_level",
// "levels": the boxes of the levels 0..k (box_json, concatenated per level)}, where k is the
// deepest level with at most `max_boxes` boxes in levels 0..k, or `level` if deeper.
[[nodiscard]] nlohmann::json tree_json(const std::string& fitter, const BuildResult& built, std::size_t level,
                                       std::size_t max_boxes = kMaxDrawnBoxes);

// The scene of `tightbvh view`: {"kind": "trees", "title", "mesh", "level", "trees": [tree_json]}.
[[nodiscard]] nlohmann::json trees_scene(const std::string& title, const Mesh& mesh, std::size_t level,
                                         nlohmann::json trees);

// The scene of `tightbvh collide --view`: {"kind": "contacts", "title", "meshes": [A, B] (B posed
// into A's frame), "contacts": [corners of A's touching triangles, of B's], "result": {...}}; with
// QueryOptions::contacts also "curve": the intersection curve's segments (6 numbers each, A's
// frame) and result.curve_length.
struct ContactInput {
  const Mesh& a;
  const Mesh& b;
  const Pose& pose_b;  // B in A's frame
  const QueryResult& result;
  bool all_pairs = false;
};
[[nodiscard]] nlohmann::json contacts_scene(const std::string& title, const ContactInput& input);

// The scene of `tightbvh distance --view`: {"kind": "distance", "title", "meshes": [A, B] (B posed
// into A's frame), "contacts": [corners of A's closest triangle, of B's] (none when no pair is the
// answer), "closest": [point on A, point on B] (6 numbers, A's frame; empty beyond the upper bound),
// "result": {"distance", "beyond_upper_bound", "inside", "node_pairs", "triangle_pairs"}}.
struct DistanceInput {
  const Mesh& a;
  const Mesh& b;
  const Pose& pose_b;  // B in A's frame (A at the identity: the result's world frame is A's)
  const DistanceResult& result;
};
[[nodiscard]] nlohmann::json distance_scene(const std::string& title, const DistanceInput& input);

// The descent of the query (collide_trace with A at the identity and B at pose_b), for the
// contacts page: {"visited", "drawn" (pairs below), "max_drawn", "per_level": [[culled, descended,
// leaves, hit] per descent level], "boxes_a", "boxes_b" (box_json of each node drawn, concatenated;
// B's posed into A's frame), "steps": 4 numbers per drawn pair in visiting order: index into
// boxes_a, index into boxes_b, outcome (PairOutcome as a number), descent level}.
[[nodiscard]] nlohmann::json descent_json(const CollideTrace& trace, const Tree& a, const Tree& b, const Pose& pose_b,
                                          std::size_t max_pairs = kMaxDrawnPairs);

}  // namespace tightbvh::view
