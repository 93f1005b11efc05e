// Bullet: btGImpactMeshShape pairs through btGImpactCollisionAlgorithm, queried with
// btCollisionWorld::contactPairTest. GImpact has no early exit and reports contact points (not
// triangle pairs); the pairs are read from the (partId, index) identifiers of each point.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "bench.hpp"
#include "bullet_shape.hpp"

namespace tightbvh::bench {
namespace {

struct BulletMesh {
  BulletShape geometry;
  btCollisionObject object;

  explicit BulletMesh(const Mesh& mesh) : geometry(mesh) { object.setCollisionShape(geometry.shape.get()); }
};

struct PairCollector final : btCollisionWorld::ContactResultCallback {
  const btCollisionObject* a = nullptr;
  std::vector<Pair>* out = nullptr;
  bool any = false;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper* w0, int, int index0,
                           const btCollisionObjectWrapper*, int, int index1) override {
    if (cp.getDistance() > 0) return 0;  // a closest point, not a contact
    any = true;
    if (out) {
      if (w0->getCollisionObject() == a) out->emplace_back(std::uint32_t(index0), std::uint32_t(index1));
      else out->emplace_back(std::uint32_t(index1), std::uint32_t(index0));
    }
    return 0;
  }
};

class BulletAdapter {
 public:
  explicit BulletAdapter(const Input& in)
      : dispatcher_(&config_), world_(&dispatcher_, &broadphase_, &config_), a_(in.a), b_(in.b) {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher_);
    // contactPairTest asks for the closest-point algorithm: register GImpact for it too.
    static btGImpactCollisionAlgorithm::CreateFunc create;
    for (int i = 0; i < MAX_BROADPHASE_COLLISION_TYPES; ++i) {
      dispatcher_.registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, i, &create);
      dispatcher_.registerClosestPointsCreateFunc(i, GIMPACT_SHAPE_PROXYTYPE, &create);
    }
  }

  [[nodiscard]] bool first_hit(const Pose& pose) {
    PairCollector c;
    c.a = &a_.object;
    query(pose, c);
    return c.any;
  }

  void all_pairs(const Pose& pose, std::vector<Pair>& out) {
    PairCollector c;
    c.a = &a_.object;
    c.out = &out;
    query(pose, c);
  }

 private:
  void query(const Pose& pose, PairCollector& c) {
    const Mat3& r = pose.rotation;
    btTransform tf(btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                   btVector3(pose.translation.x(), pose.translation.y(), pose.translation.z()));
    b_.object.setWorldTransform(tf);
    world_.contactPairTest(&a_.object, &b_.object, c);
  }

  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btCollisionWorld world_;
  BulletMesh a_, b_;
};

}  // namespace

std::vector<EngineInfo> bullet_engines() {
  return {{"bullet-gimpact", false, true,
           "no early exit: first_hit is not offered (yes/no is read from the all_pairs run); "
           "pairs are the (index0, index1) of reported contact points with distance <= 0",
           [](const Input& in) { return prepare([&] { return std::make_unique<BulletAdapter>(in); }); }}};
}

}  // namespace tightbvh::bench
