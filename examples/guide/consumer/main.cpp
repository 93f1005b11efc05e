// The smallest program against an installed tightbvh: a tree over one tetrahedron.
#include <tightbvh/build.hpp>
#include <tightbvh/mesh.hpp>

#include <cstdio>

int main() {
  tightbvh::Mesh mesh;
  mesh.vertices = {tightbvh::Vec3(0, 0, 0), tightbvh::Vec3(1, 0, 0), tightbvh::Vec3(0, 1, 0), tightbvh::Vec3(0, 0, 1)};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const tightbvh::Tree tree = tightbvh::build(mesh);
  std::printf("installed tightbvh: %zu nodes\n", tree.nodes.size());
  return tree.nodes.size() == 7 ? 0 : 1;  // leaf size 1: 4 leaves and 3 internal nodes
}
