#pragma once
// A Bullet GImpact shape over a tightbvh mesh, margin 0: the one setup of Bullet as a peer, shared
// by tightbvh-bench's pair queries (engines_bullet.cpp) and its scenes (bench/scene/scene_vs_peers.cpp). Bullet keeps pointers into
// the vertex and index arrays, so they live here with the shape.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include <memory>
#include <vector>

#include "tightbvh/mesh.hpp"

namespace tightbvh::bench {

struct BulletShape {
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> array;
  std::unique_ptr<btGImpactMeshShape> shape;

  explicit BulletShape(const Mesh& mesh) {
    for (const Vec3& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
    for (const Triangle& t : mesh.triangles) indices.insert(indices.end(), {int(t[0]), int(t[1]), int(t[2])});
    array = std::make_unique<btTriangleIndexVertexArray>(int(mesh.triangles.size()), indices.data(),
                                                         int(3 * sizeof(int)), int(mesh.vertices.size()),
                                                         vertices.data(), int(3 * sizeof(btScalar)));
    shape = std::make_unique<btGImpactMeshShape>(array.get());
    shape->setMargin(0);  // exact geometry, like every other engine here (default is 0.04)
    shape->updateBound();  // builds GImpact's box tree
  }
};

}  // namespace tightbvh::bench
