#pragma once
/// @file
/// Triangle soup: vertices + index triples. No connectivity is assumed anywhere.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/error.hpp"

namespace tightbvh {

/// A triangle: three indices into Mesh::vertices.
using Triangle = std::array<std::uint32_t, 3>;

/// A triangle mesh in its own frame (the mesh frame): vertices and index triples, with no
/// connectivity assumed. Valid when check_mesh() passes.
struct Mesh {
  std::vector<Vec3> vertices;       ///< Positions (finite), in the mesh frame.
  std::vector<Triangle> triangles;  ///< Index triples into `vertices`.

  /// The three corners of triangle `triangle` (< triangles.size(), unchecked).
  [[nodiscard]] std::array<Vec3, 3> corners(std::size_t triangle) const {
    const Triangle& t = triangles[triangle];
    return {vertices[t[0]], vertices[t[1]], vertices[t[2]]};
  }
};

/// The corners of every triangle, three per triangle in triangle order: the triangle soup the
/// fitters take (fit_triangles).
[[nodiscard]] std::vector<Vec3> triangle_corners(const Mesh& mesh);
/// The same for the listed triangles only, into `out` (its contents replaced, its memory reused).
void triangle_corners(const Mesh& mesh, std::span<const std::uint32_t> triangles, std::vector<Vec3>& out);

/// What check_mesh() reports about a valid mesh.
struct MeshStats {
  std::size_t vertices = 0;              ///< The number of vertices.
  std::size_t triangles = 0;             ///< The number of triangles.
  std::size_t degenerate_triangles = 0;  ///< zero area (kept, but counted)
  Aabb bounds;                           ///< Of the vertices, in the mesh frame.
};

/// Loads OBJ, OFF, STL or PLY (by extension; files without one are recognised by content) through
/// assimp: polygons triangulated, sub-meshes merged, points and lines dropped. OFF coordinates
/// keep the file's double precision; OBJ, STL and PLY ones pass through assimp's single precision.
/// OBJ and STL corners that assimp duplicates are welded back (exactly equal positions only); OFF
/// and PLY keep the file's vertices (OFF also their order).
/// Throws InputError `"<path>: <problem>"` for a missing file, a directory, an unknown format, an
/// empty, malformed or truncated file, non-finite coordinates, out-of-range indices or no
/// triangles. The result has passed check_mesh(); degenerate triangles are kept.
[[nodiscard]] Mesh load_mesh(const std::filesystem::path& path);

/// Checks `mesh` and returns its statistics. Throws InputError on NaN/Inf coordinates, indices
/// out of range or zero triangles.
/// `source` names the mesh in messages.
MeshStats check_mesh(const Mesh& mesh, const std::string& source = "mesh");

/// check_mesh's checks and messages without its statistics (bounds, degenerate triangles): for
/// callers that check a mesh every frame, such as refit.
void require_valid_mesh(const Mesh& mesh, const std::string& source = "mesh");

/// Midpoint subdivision (Loop's split without smoothing): every triangle (a, b, c) becomes
/// (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca), with one new vertex per edge shared by the
/// triangles of that edge. Makes large test meshes, and the flat patches of nearly coplanar
/// midpoints that subdivided, remeshed and CAD meshes have.
[[nodiscard]] Mesh subdivide_midpoints(const Mesh& mesh);

}  // namespace tightbvh
