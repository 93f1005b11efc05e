#include "tightbvh/mesh.hpp"

#include <cmath>
#include <sstream>

namespace tightbvh {

MeshStats check_mesh(const Mesh& mesh, const std::string& source) {
  if (mesh.triangles.empty()) throw InputError(source + ": no triangles");
  MeshStats stats;
  stats.vertices = mesh.vertices.size();
  stats.triangles = mesh.triangles.size();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    if (!v.allFinite()) {
      std::ostringstream msg;
      msg << source << ": vertex " << i << " has a non-finite coordinate (" << v.x() << ", " << v.y() << ", "
          << v.z() << ")";
      throw InputError(msg.str());
    }
    stats.bounds.extend(v);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t index : mesh.triangles[t]) {
      if (index >= mesh.vertices.size()) {
        std::ostringstream msg;
        msg << source << ": triangle " << t << ": vertex index " << index << " is out of range (the mesh has "
            << mesh.vertices.size() << " vertices)";
        throw InputError(msg.str());
      }
    }
    const auto [a, b, c] = mesh.corners(t);
    if ((b - a).cross(c - a).squaredNorm() == 0.0) ++stats.degenerate_triangles;
  }
  return stats;
}

}  // namespace tightbvh
