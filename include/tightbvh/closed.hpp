#pragma once
/// @file
/// Closed meshes: the check that a triangle mesh bounds a solid, done once per mesh.
///
/// A mesh is closed when every edge (a pair of vertex indices) is shared by exactly two
/// triangles that run along it in opposite directions: watertight and consistently oriented.
/// Connectivity is by vertex index: vertices at equal positions but with different indices are
/// different vertices (load_mesh welds the formats that duplicate corners). Triangles that
/// repeat a vertex index are points or segments, bound nothing, and are ignored here (a
/// zero-area triangle with three distinct indices is an ordinary triangle of the surface).
///
/// The solid queries (QueryOptions::solid, DistanceOptions::solid, inside.hpp) need closed
/// meshes: they take the Closedness of each mesh, computed once by check_closed() and passed
/// by pointer, so that no query pays for it (O(n log n) in the triangles).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tightbvh/mesh.hpp"

namespace tightbvh {

/// The result of check_closed(): whether a mesh is closed, and if not why.
struct Closedness {
  bool closed = false;                ///< Watertight and consistently oriented (see the file comment).
  std::size_t boundary_edges = 0;     ///< edges of exactly one triangle
  std::size_t nonmanifold_edges = 0;  ///< edges of three or more triangles
  std::size_t misoriented_edges = 0;  ///< edges of two triangles running along it in the same direction
  /// Why the mesh is not closed, "" when it is; for example `"12 boundary edges, e.g. (3, 7)"` or
  /// `"inconsistently oriented at edge (3, 7): triangles 10 and 12 both run 3 -> 7"`.
  std::string problem;
  /// One vertex per piece of the surface (triangles connected through shared vertices), the
  /// lowest index of each piece, ascending. A closed piece that does not touch another surface
  /// lies wholly inside or wholly outside its solid, so one point per piece decides it.
  std::vector<std::uint32_t> pieces;
  /// The vertex count of the mesh checked: a Closedness passed with a mesh of other counts is an
  /// InputError.
  std::size_t vertex_count = 0;
  std::size_t triangle_count = 0;  ///< The triangle count of the mesh checked (see vertex_count).
};

/// The check of `mesh`; never throws for a valid mesh (an open mesh gives closed == false).
[[nodiscard]] Closedness check_closed(const Mesh& mesh);

/// Throws InputError `"<who>: mesh <which> is not closed: <problem>"` unless `closedness` is closed
/// and was computed for a mesh with `mesh`'s vertex and triangle counts.
void require_closed(const Closedness& closedness, const Mesh& mesh, const std::string& who, const std::string& which);

}  // namespace tightbvh
