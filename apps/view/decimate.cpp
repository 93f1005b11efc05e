#include "view/decimate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

namespace tightbvh::view {
namespace {

// Finer grids are never needed: a surface on 4096^2 cells has tens of millions of triangles.
constexpr std::size_t kMaxCells = 4096;

// The mesh clustered on a grid of `cells` cells along the longest side of `bounds`.
Mesh cluster(const Mesh& mesh, const Aabb& bounds, std::size_t cells) {
  const double cell = std::max(bounds.extents().maxCoeff() / static_cast<double>(cells), 1e-300);
  const auto key_of = [&](const Vec3& p) {
    const Vec3 q = ((p - bounds.min) / cell).array().floor();
    const auto clamp = [&](double v) { return static_cast<std::uint64_t>(std::clamp(v, 0.0, double(kMaxCells))); };
    return clamp(q.x()) | clamp(q.y()) << 21 | clamp(q.z()) << 42;
  };
  Mesh out;
  std::vector<double> members;
  std::unordered_map<std::uint64_t, std::uint32_t> cell_vertex;
  std::vector<std::uint32_t> vertex_of(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const auto [it, added] = cell_vertex.try_emplace(key_of(mesh.vertices[i]), std::uint32_t(out.vertices.size()));
    if (added) {
      out.vertices.push_back(Vec3::Zero());
      members.push_back(0.0);
    }
    out.vertices[it->second] += mesh.vertices[i];
    members[it->second] += 1.0;
    vertex_of[i] = it->second;
  }
  for (std::size_t v = 0; v < out.vertices.size(); ++v) out.vertices[v] /= members[v];
  // Collapsed triangles vanish; two triangles on the same three cells are drawn once (the key is
  // exact below 2^21 cells; more cells never happen on grids within the budget, else a duplicate is
  // only drawn twice).
  const bool dedupe = out.vertices.size() < (std::size_t{1} << 21);
  std::unordered_set<std::uint64_t> seen;
  for (const Triangle& t : mesh.triangles) {
    const Triangle c{vertex_of[t[0]], vertex_of[t[1]], vertex_of[t[2]]};
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    std::array<std::uint64_t, 3> s{c[0], c[1], c[2]};
    std::sort(s.begin(), s.end());
    if (dedupe && !seen.insert(s[0] | s[1] << 21 | s[2] << 42).second) continue;
    out.triangles.push_back(c);
  }
  return out;
}

}  // namespace

DrawnMesh decimate_for_drawing(const Mesh& mesh, std::size_t max_triangles) {
  if (max_triangles == 0) throw InputError("decimate: the triangle budget must be positive");
  check_mesh(mesh);
  if (mesh.triangles.size() <= max_triangles) return {mesh, false, 0};
  const Aabb bounds = bounds_of(mesh.vertices);
  // The count grows with the grid (roughly as cells^2 on a surface): binary search for the finest
  // grid within the budget, keeping the best one seen (growth is not strictly monotone).
  DrawnMesh best{cluster(mesh, bounds, 1), true, 1};
  std::size_t lo = 2, hi = kMaxCells;
  while (lo <= hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    Mesh candidate = cluster(mesh, bounds, mid);
    if (candidate.triangles.size() <= max_triangles) {
      if (candidate.triangles.size() >= best.mesh.triangles.size()) best = {std::move(candidate), true, mid};
      lo = mid + 1;
    } else {
      hi = mid - 1;
    }
  }
  return best;
}

}  // namespace tightbvh::view
