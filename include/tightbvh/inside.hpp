#pragma once
/// @file
/// Point in solid: is a point inside the solid bounded by a closed mesh (closed.hpp)?
///
/// Exact ray parity. A segment from the point to a point beyond the mesh's root box is tested
/// against the triangles under the boxes it meets (a slab test with collide()'s rounding
/// allowance, so no triangle it meets is culled); each triangle is classified with exact
/// orientation predicates (Shewchuk-style, src/geometry/predicates.hpp): the segment crosses
/// the triangle's interior transversally (orient3d of both ends against the triangle's plane
/// nonzero and opposite, and the three orient3d(p, q, edge) of one strict sign), misses it, or
/// meets it degenerately (through an edge or a vertex, within its plane, or ending on it). One
/// degenerate meeting and the ray is re-shot in another direction: first +x, then a fixed
/// pseudo-random sequence, so the answer is deterministic. The parity of the transversal
/// crossings is then the exact answer for the double coordinates given: no error bound needed.
/// Points on the surface are reported as such (decided exactly as well).
///
/// Self-intersecting closed meshes are answered by parity (a point is inside when a generic ray
/// from it crosses the surface an odd number of times).
#include <cstdint>

#include "tightbvh/closed.hpp"
#include "tightbvh/math.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// Where a point is relative to the solid a closed mesh bounds.
enum class Containment : std::uint8_t {
  outside,     ///< in the open exterior
  inside,      ///< in the open interior
  on_surface,  ///< on a triangle (its interior, an edge or a vertex)
};

/// Whether `p` is inside, outside or on the surface of the solid bounded by `mesh` (exact, as
/// described above). `p` in the mesh frame; `tree` built over `mesh`; `closedness` = check_closed(mesh) (InputError
/// when the mesh is not closed or the check is of another mesh). Empty tree: outside.
[[nodiscard]] Containment classify_point(const Tree& tree, const Mesh& mesh, const Closedness& closedness,
                                         const Vec3& p);

/// Reference: the same classification over every triangle (no tree).
[[nodiscard]] Containment classify_point_brute_force(const Mesh& mesh, const Closedness& closedness, const Vec3& p);

/// The enumerator's name: "outside", "inside" or "on_surface".
[[nodiscard]] const char* to_string(Containment c);

}  // namespace tightbvh
