#pragma once
// Fewer triangles for drawing (never for measuring): vertex clustering (Rossignac & Borrel 1993).
// Vertices are snapped to a uniform grid, each occupied cell becomes one vertex (the mean of its
// vertices), and triangles whose corners fall into fewer than three cells disappear. The grid is
// refined until the largest count under the budget is found, so the shape stays recognisable.
#include <cstddef>

#include "tightbvh/mesh.hpp"

namespace tightbvh::view {

// Above this many triangles the pages draw a decimated mesh (and say so).
inline constexpr std::size_t kMaxDrawnTriangles = 50'000;

struct DrawnMesh {
  Mesh mesh;               // what is drawn
  bool decimated = false;  // false: `mesh` is the input
  std::size_t cells = 0;   // grid cells along the longest side of the bounds (decimated only)
};

// The input itself when it has at most `max_triangles` triangles; else a clustered mesh with at
// most `max_triangles` triangles (at least one unless max_triangles is 0). Throws InputError for
// max_triangles == 0 or an invalid mesh (check_mesh).
[[nodiscard]] DrawnMesh decimate_for_drawing(const Mesh& mesh, std::size_t max_triangles = kMaxDrawnTriangles);

}  // namespace tightbvh::view
