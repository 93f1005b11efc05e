#pragma once
// Internal: the solid part of collide() and distance() (QueryOptions::solid,
// DistanceOptions::solid): after a descent that found no contact, is a piece of one mesh inside
// the other's solid? Implemented in inside.cpp.
#include <cstdint>
#include <optional>
#include <vector>

#include "tightbvh/closed.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/inside.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/tree.hpp"
#include "wide_nodes.hpp"

namespace tightbvh::query_detail {

struct SolidHit {
  Inside inside = Inside::none;
  Vec3 point_a_frame = Vec3::Zero();  // the piece's vertex that lies in the other solid, A's frame
  Vec3 point_b_frame = Vec3::Zero();  // the same point, B's frame
};

// The closedness of both meshes: the caller's (checked to belong to the meshes) or, when not
// given, computed here (once per query: O(n log n); the batch functions compute it once for all
// poses). Throws InputError "<query>: mesh A|B is not closed: ..." for an open mesh.
class SolidMeshes {
 public:
  SolidMeshes(const char* query, const Mesh& ma, const Closedness* given_a, const Mesh& mb, const Closedness* given_b);
  SolidMeshes(const SolidMeshes&) = delete;
  SolidMeshes& operator=(const SolidMeshes&) = delete;

  // With the trees: a piece of B inside A's solid (tested first), or a piece of A inside B's.
  // Each test takes one vertex per piece; B's vertices are mapped into A's frame by map_point,
  // as every triangle test of the queries, so all tests see the same triangles. Meant for poses
  // where no triangles touch; a piece vertex on the other surface also counts as inside.
  [[nodiscard]] SolidHit overlap(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel) const;
  // The same without trees (every triangle): the brute-force references.
  [[nodiscard]] SolidHit overlap_brute_force(const Mesh& ma, const Mesh& mb, const Pose& rel) const;

  [[nodiscard]] const Closedness& a() const { return *a_; }
  [[nodiscard]] const Closedness& b() const { return *b_; }

 private:
  std::optional<Closedness> own_a_, own_b_;
  const Closedness* a_ = nullptr;
  const Closedness* b_ = nullptr;
};

// classify_point() for a mesh whose closedness and tree the caller checked, with the caller's
// stack (no allocation per point in a batch).
[[nodiscard]] Containment classify_point_checked(const Tree& tree, const Mesh& mesh, const Vec3& p,
                                                 std::vector<std::uint32_t>& stack);

// A node of `wide` to visit, with its reference point (child_ref, as the builder made it).
struct WideRayItem {
  std::int32_t node;
  Vec3 ref;
};
// What classify_point_wide needs of the trees for every point, computed once: the root's box, its
// scale for the containment margin, and the kernel's frame (the identity).
struct WideRays {
  WideRays(const Tree& tree, const WideTree& wide);
  Obb root;
  double root_scale;
  WideFrame frame;
};
// classify_point_checked over the tree's wide nodes (`wide` = build_wide(tree), `rays` of both):
// the first ray, along a coordinate axis, meets the nodes' boxes four at a time in the float
// kernel (the segment is a box of extents (L/2, 0, 0): inside.cpp); a ray that meets the surface
// degenerately goes to classify_point_checked. The same answer (parity is exact for any ray that
// meets no edge or vertex).
[[nodiscard]] Containment classify_point_wide(const Tree& tree, const WideTree& wide, const WideRays& rays,
                                              const Mesh& mesh, const Vec3& p, std::vector<WideRayItem>& wide_stack,
                                              std::vector<std::uint32_t>& stack);

}  // namespace tightbvh::query_detail
