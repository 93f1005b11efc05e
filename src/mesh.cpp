#include "tightbvh/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

namespace tightbvh {

namespace {

[[noreturn]] void fail_non_finite(const std::string& source, std::size_t i, const Vec3& v) {
  std::ostringstream msg;
  msg << source << ": vertex " << i << " has a non-finite coordinate (" << v.x() << ", " << v.y() << ", " << v.z()
      << ")";
  throw InputError(msg.str());
}

[[noreturn]] void fail_index(const std::string& source, std::size_t t, std::uint32_t index, std::size_t vertices) {
  std::ostringstream msg;
  msg << source << ": triangle " << t << ": vertex index " << index << " is out of range (the mesh has " << vertices
      << " vertices)";
  throw InputError(msg.str());
}

}  // namespace

void require_valid_mesh(const Mesh& mesh, const std::string& source) {
  if (mesh.triangles.empty()) throw InputError(source + ": no triangles");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite()) fail_non_finite(source, i, mesh.vertices[i]);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t index : mesh.triangles[t])
      if (index >= mesh.vertices.size()) fail_index(source, t, index, mesh.vertices.size());
}

MeshStats check_mesh(const Mesh& mesh, const std::string& source) {
  if (mesh.triangles.empty()) throw InputError(source + ": no triangles");
  MeshStats stats;
  stats.vertices = mesh.vertices.size();
  stats.triangles = mesh.triangles.size();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    if (!v.allFinite()) fail_non_finite(source, i, v);
    stats.bounds.extend(v);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t index : mesh.triangles[t])
      if (index >= mesh.vertices.size()) fail_index(source, t, index, mesh.vertices.size());
    const auto [a, b, c] = mesh.corners(t);
    if ((b - a).cross(c - a).squaredNorm() == 0.0) ++stats.degenerate_triangles;
  }
  return stats;
}

std::vector<Vec3> triangle_corners(const Mesh& mesh) {
  std::vector<Vec3> out;
  out.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const Vec3& c : mesh.corners(t)) out.push_back(c);
  return out;
}

void triangle_corners(const Mesh& mesh, std::span<const std::uint32_t> triangles, std::vector<Vec3>& out) {
  out.clear();
  out.reserve(3 * triangles.size());
  for (const std::uint32_t t : triangles)
    for (const Vec3& c : mesh.corners(t)) out.push_back(c);
}

Mesh subdivide_midpoints(const Mesh& mesh) {
  Mesh out;
  out.vertices = mesh.vertices;
  out.triangles.reserve(mesh.triangles.size() * 4);
  std::unordered_map<std::uint64_t, std::uint32_t> midpoint;
  midpoint.reserve(mesh.triangles.size() * 2);
  const auto mid = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
    const auto [it, inserted] = midpoint.try_emplace(key, static_cast<std::uint32_t>(out.vertices.size()));
    if (inserted) out.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
    return it->second;
  };
  for (const Triangle& t : mesh.triangles) {
    const std::uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace tightbvh
