// Closedness of a triangle mesh (watertight, consistently oriented). See include/tightbvh/closed.hpp.
#include "tightbvh/closed.hpp"

#include <algorithm>
#include <numeric>
#include <string>

#include "tightbvh/error.hpp"

namespace tightbvh {
namespace {

// One directed edge of a triangle: `key` = (lower index << 32) | higher index, `forward` when it
// runs from the lower index to the higher.
struct HalfEdge {
  std::uint64_t key;
  std::uint32_t triangle;
  bool forward;
};

std::string edge_text(std::uint64_t key) {
  std::string text = "(";  // appended piecewise: GCC 12 warns (-Wrestrict, falsely) on "(" + std::string
  text += std::to_string(key >> 32);
  text += ", ";
  text += std::to_string(key & 0xffffffffu);
  text += ")";
  return text;
}

// Union-find over vertex indices (path halving, union by index: the root is the lowest vertex).
std::uint32_t find(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

}  // namespace

Closedness check_closed(const Mesh& mesh) {
  Closedness out;
  out.vertex_count = mesh.vertices.size();
  out.triangle_count = mesh.triangles.size();
  std::vector<HalfEdge> edges;
  edges.reserve(3 * mesh.triangles.size());
  std::vector<std::uint32_t> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0u);
  std::vector<std::uint8_t> used(mesh.vertices.size(), 0);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;  // a point or a segment
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t from = tri[k], to = tri[(k + 1) % 3];
      const std::uint32_t lo = std::min(from, to), hi = std::max(from, to);
      edges.push_back({(std::uint64_t{lo} << 32) | hi, t, from < to});
      used[from] = 1;
      const std::uint32_t ra = find(parent, from), rb = find(parent, to);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  std::sort(edges.begin(), edges.end(), [](const HalfEdge& l, const HalfEdge& r) {
    return l.key != r.key ? l.key < r.key : l.triangle < r.triangle;
  });
  std::string boundary, nonmanifold, misoriented;  // the first example of each
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    const std::size_t n = j - i;
    if (n == 1) {
      if (out.boundary_edges++ == 0) boundary = edge_text(edges[i].key);
    } else if (n > 2) {
      if (out.nonmanifold_edges++ == 0)
        nonmanifold = edge_text(edges[i].key) + " (" + std::to_string(n) + " triangles)";
    } else if (edges[i].forward == edges[i + 1].forward) {
      if (out.misoriented_edges++ == 0) {
        const std::uint64_t lo = edges[i].key >> 32, hi = edges[i].key & 0xffffffffu;
        const std::uint64_t from = edges[i].forward ? lo : hi, to = edges[i].forward ? hi : lo;
        misoriented = edge_text(edges[i].key) + ": triangles " + std::to_string(edges[i].triangle) + " and " +
                      std::to_string(edges[i + 1].triangle) + " both run " + std::to_string(from) + " -> " +
                      std::to_string(to);
      }
    }
    i = j;
  }
  const auto add = [&](const std::string& text) { out.problem += (out.problem.empty() ? "" : "; ") + text; };
  if (out.boundary_edges > 0)
    add(std::to_string(out.boundary_edges) + " boundary edge" + (out.boundary_edges > 1 ? "s" : "") +
        " (of one triangle only), e.g. " + boundary);
  if (out.nonmanifold_edges > 0)
    add(std::to_string(out.nonmanifold_edges) + " edge" + (out.nonmanifold_edges > 1 ? "s" : "") +
        " shared by more than two triangles, e.g. " + nonmanifold);
  if (out.misoriented_edges > 0)
    add("inconsistently oriented at edge " + misoriented +
        (out.misoriented_edges > 1 ? " (" + std::to_string(out.misoriented_edges) + " such edges)" : ""));
  if (edges.empty()) add("no triangle with three distinct vertices");
  out.closed = out.problem.empty();
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (used[v] && find(parent, v) == v) out.pieces.push_back(v);
  return out;
}

void require_closed(const Closedness& closedness, const Mesh& mesh, const std::string& who, const std::string& which) {
  if (closedness.vertex_count != mesh.vertices.size() || closedness.triangle_count != mesh.triangles.size())
    throw InputError(who + ": the closedness given for mesh " + (which.empty() ? "" : which + " ") +
                     "is of another mesh (" + std::to_string(closedness.vertex_count) + " vertices, " +
                     std::to_string(closedness.triangle_count) + " triangles; the mesh has " +
                     std::to_string(mesh.vertices.size()) + " and " + std::to_string(mesh.triangles.size()) + ")");
  if (!closedness.closed)
    throw InputError(who + ": mesh " + (which.empty() ? "" : which + " ") + "is not closed: " + closedness.problem);
}

}  // namespace tightbvh
