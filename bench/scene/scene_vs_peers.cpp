// tightbvh-bench --scene: a scene file (scene_file.hpp) collided by tightbvh's Scene, FCL's
// DynamicAABBTreeCollisionManager (BVHModel<OBBRSS> objects: FCL's own trees, and ours exported into
// FCL, engine fcl-export) and Bullet's btCollisionWorld with
// btDbvtBroadphase and btGImpactMeshShape objects. Every engine's touching object pairs, for the
// initial poses and after every frame of moves, are checked against brute force: the pair query
// collide(model_a, pose_a, model_b, pose_b) on every tested object pair, skipping only pairs
// whose vertex-bounding spheres are disjoint (which cannot touch).
//
// Timing: thread CPU time (bench/thread_clock.hpp), median of --reps repetitions. Without frames,
// one check is one self-collision of the unchanged scene (checks/s), and again with every object
// moved before each check, alternately to its initial pose and to that pose shifted by a small
// step (SceneData::stepped: all moved/s); with frames, one repetition
// runs every frame: the moves (set_poses; setTransform + computeAABB + update; setWorldTransform)
// and the self-collision that follows (frames/s).
//
//     tightbvh-bench --scene out/scenes/a-touching.json [--json OUT] [--reps N] [--engines tightbvh,fcl]
//                             [--memory-objects N --memory-models M] [--step S]
//
// Memory: the scene's Scene::model_bytes() (each distinct model once) and Scene::own_bytes() (the
// scene layer: objects, index, names, allowed pairs, top-level tree), against the bytes the
// objects' models would take if each object had its own copy. --memory-objects N adds the same
// report for a scene of N objects sharing the file's first M models (object i: model i mod M at
// the pose of file object i mod objects, shifted per round so that no two boxes coincide).
//
// Exit status 1 when tightbvh's pairs differ from brute force, 2 on bad input.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <variant>
#include <vector>

#include "scene_vs_peers.hpp"
#include "../query/bullet_shape.hpp"  // BulletShape: the same Bullet setup as the pair benchmark
#include "../thread_clock.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/fcl/export.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/scene_file.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh::bench {
namespace {

using bench_support::thread_seconds;
using IndexPair = std::pair<std::uint32_t, std::uint32_t>;  // object indices (file order), first < second

// The scene as plain arrays: object i is the i-th id of the loaded scene.
struct SceneData {
  std::vector<ObjectId> ids;
  std::vector<ModelPtr> models;               // per object (null for a shape)
  std::vector<std::optional<Shape>> shapes;   // per object (set for a shape)
  std::vector<Pose> poses;                    // initial poses
  std::vector<Pose> stepped;                  // the same shifted by a small step (all moved/s)
  std::vector<std::vector<std::pair<std::uint32_t, Pose>>> frames;  // per frame: (index, pose)
  std::unordered_set<std::uint64_t> allowed;                         // key(i, j)
  std::vector<ModelPtr> distinct;                                    // each model once (shapes: none)
  [[nodiscard]] static std::uint64_t key(std::uint32_t i, std::uint32_t j) {
    if (i > j) std::swap(i, j);
    return (std::uint64_t(i) << 32) | j;
  }
  [[nodiscard]] bool is_allowed(std::uint32_t i, std::uint32_t j) const { return allowed.count(key(i, j)) != 0; }
};

using PairsPerFrame = std::vector<std::vector<IndexPair>>;  // [0]: initial poses, then one per frame

// An engine holds its own copy of the scene; place() moves every object (object i to poses[i]),
// reset() puts the initial poses back, check() collides the scene (appending the touching pairs),
// move() applies one frame.
class Engine {
 public:
  virtual ~Engine() = default;
  virtual void place(const std::vector<Pose>& poses) = 0;
  virtual void reset() = 0;
  virtual void move(std::size_t frame) = 0;
  virtual void check(std::vector<IndexPair>& out) = 0;
};

class TightbvhEngine final : public Engine {
 public:
  explicit TightbvhEngine(const SceneData& d, const Scene& scene) : d_(d), scene_(scene) {
    for (std::uint32_t i = 0; i < d.ids.size(); ++i) index_[d.ids[i]] = i;
    for (const auto& frame : d.frames) {
      std::vector<ObjectId> ids;
      std::vector<Pose> poses;
      for (const auto& [i, p] : frame) ids.push_back(d.ids[i]), poses.push_back(p);
      frame_ids_.push_back(std::move(ids));
      frame_poses_.push_back(std::move(poses));
    }
  }
  void place(const std::vector<Pose>& poses) override { scene_.set_poses(d_.ids, poses); }
  void reset() override { place(d_.poses); }
  void move(std::size_t f) override { scene_.set_poses(frame_ids_[f], frame_poses_[f]); }
  void check(std::vector<IndexPair>& out) override {
    for (const ObjectPairHit& h : collide(scene_, QueryOptions{}, 1)) {
      std::uint32_t a = index_.at(h.a), b = index_.at(h.b);
      out.emplace_back(std::min(a, b), std::max(a, b));
    }
  }

 private:
  const SceneData& d_;
  Scene scene_;
  std::map<ObjectId, std::uint32_t> index_;
  std::vector<std::vector<ObjectId>> frame_ids_;
  std::vector<std::vector<Pose>> frame_poses_;
};

[[nodiscard]] fcl::Transform3<double> fcl_transform(const Pose& pose) {
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.linear() = pose.rotation;
  tf.translation() = pose.translation;
  return tf;
}

struct FclShape {
  std::shared_ptr<fcl::CollisionGeometry<double>> operator()(const Sphere& s) const {
    return std::make_shared<fcl::Sphere<double>>(s.radius);
  }
  std::shared_ptr<fcl::CollisionGeometry<double>> operator()(const Box& s) const {
    return std::make_shared<fcl::Box<double>>(s.size.x(), s.size.y(), s.size.z());
  }
  std::shared_ptr<fcl::CollisionGeometry<double>> operator()(const Capsule& s) const {
    return std::make_shared<fcl::Capsule<double>>(s.radius, s.length);
  }
  std::shared_ptr<fcl::CollisionGeometry<double>> operator()(const Cylinder& s) const {
    return std::make_shared<fcl::Cylinder<double>>(s.radius, s.length);
  }
  std::shared_ptr<fcl::CollisionGeometry<double>> operator()(const Convex& s) const {
    auto vertices = std::make_shared<std::vector<fcl::Vector3<double>>>(s.vertices.begin(), s.vertices.end());
    auto faces = std::make_shared<std::vector<int>>();  // FCL's layout: count, then the indices
    for (const auto& f : s.faces) faces->insert(faces->end(), {3, int(f[0]), int(f[1]), int(f[2])});
    return std::make_shared<fcl::Convex<double>>(vertices, int(s.faces.size()), faces);
  }
};

class FclEngine final : public Engine {
 public:
  using Bv = fcl::OBBRSS<double>;
  // exported: each model's tree as tightbvh built it, exported into FCL (to_fcl_obbrss,
  // tightbvh/fcl/export.hpp); otherwise FCL's own tree (its default splitter and fitter).
  FclEngine(const SceneData& d, bool exported) : d_(d) {
    std::map<const Model*, std::shared_ptr<fcl::BVHModel<Bv>>> geometry;
    for (const ModelPtr& m : d.distinct) {
      if (exported) {
        geometry[m.get()] = to_fcl_obbrss(m->tree(), m->mesh());
        continue;
      }
      auto g = std::make_shared<fcl::BVHModel<Bv>>();
      std::vector<fcl::Vector3<double>> vertices(m->mesh().vertices.begin(), m->mesh().vertices.end());
      std::vector<fcl::Triangle> triangles;
      for (const Triangle& t : m->mesh().triangles) triangles.emplace_back(t[0], t[1], t[2]);
      g->beginModel(int(triangles.size()), int(vertices.size()));
      g->addSubModel(vertices, triangles);
      g->endModel();
      g->computeLocalAABB();
      geometry[m.get()] = g;
    }
    for (std::uint32_t i = 0; i < d.models.size(); ++i) {
      std::shared_ptr<fcl::CollisionGeometry<double>> g;
      if (d.shapes[i]) {  // FCL's own primitives: the same conventions (shape.hpp)
        g = std::visit(FclShape{}, *d.shapes[i]);
      } else {
        g = geometry.at(d.models[i].get());
      }
      objects_.push_back(std::make_unique<fcl::CollisionObject<double>>(g, fcl_transform(d.poses[i])));
      objects_.back()->setUserData(reinterpret_cast<void*>(std::uintptr_t(i)));
      raw_.push_back(objects_.back().get());
    }
    manager_.registerObjects(raw_);
    manager_.setup();
    request_.num_max_contacts = 1;
    request_.enable_contact = false;
  }
  void place(const std::vector<Pose>& poses) override {
    for (std::uint32_t i = 0; i < raw_.size(); ++i) {
      raw_[i]->setTransform(fcl_transform(poses[i]));
      raw_[i]->computeAABB();
    }
    manager_.update();
  }
  void reset() override { place(d_.poses); }
  void move(std::size_t f) override {
    moved_.clear();
    for (const auto& [i, p] : d_.frames[f]) {
      raw_[i]->setTransform(fcl_transform(p));
      raw_[i]->computeAABB();
      moved_.push_back(raw_[i]);
    }
    manager_.update(moved_);
  }
  void check(std::vector<IndexPair>& out) override {
    out_ = &out;
    manager_.collide(this, &FclEngine::callback);
  }

 private:
  static bool callback(fcl::CollisionObject<double>* o1, fcl::CollisionObject<double>* o2, void* data) {
    auto* self = static_cast<FclEngine*>(data);
    auto i = std::uint32_t(reinterpret_cast<std::uintptr_t>(o1->getUserData()));
    auto j = std::uint32_t(reinterpret_cast<std::uintptr_t>(o2->getUserData()));
    if (self->d_.is_allowed(i, j)) return false;
    self->result_.clear();
    fcl::collide(o1, o2, self->request_, self->result_);
    if (self->result_.isCollision()) self->out_->emplace_back(std::min(i, j), std::max(i, j));
    return false;  // continue with the next pair
  }

  const SceneData& d_;
  std::vector<std::unique_ptr<fcl::CollisionObject<double>>> objects_;
  std::vector<fcl::CollisionObject<double>*> raw_, moved_;
  fcl::DynamicAABBTreeCollisionManager<double> manager_;
  fcl::CollisionRequest<double> request_;
  fcl::CollisionResult<double> result_;
  std::vector<IndexPair>* out_ = nullptr;
};

[[nodiscard]] btTransform bullet_transform(const Pose& pose) {
  const Mat3& r = pose.rotation;
  return btTransform(btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                     btVector3(pose.translation.x(), pose.translation.y(), pose.translation.z()));
}


// Bullet's primitive for a shape (btCapsuleShapeZ: along z, `height` the axis segment, as ours).
struct BulletPrimitive {
  std::unique_ptr<btCollisionShape> operator()(const Sphere& s) const { return std::make_unique<btSphereShape>(s.radius); }
  std::unique_ptr<btCollisionShape> operator()(const Box& s) const {
    auto box = std::make_unique<btBoxShape>(btVector3(0.5 * s.size.x(), 0.5 * s.size.y(), 0.5 * s.size.z()));
    box->setMargin(0);  // exact geometry, like every other engine here
    return box;
  }
  std::unique_ptr<btCollisionShape> operator()(const Capsule& s) const {
    return std::make_unique<btCapsuleShapeZ>(s.radius, s.length);
  }
  std::unique_ptr<btCollisionShape> operator()(const Cylinder& s) const {
    auto cylinder = std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, 0.5 * s.length));
    cylinder->setMargin(0);
    return cylinder;
  }
  std::unique_ptr<btCollisionShape> operator()(const Convex& s) const {
    auto hull = std::make_unique<btConvexHullShape>();
    for (const Vec3& p : s.vertices) hull->addPoint(btVector3(p.x(), p.y(), p.z()), false);
    hull->recalcLocalAabb();
    hull->setMargin(0);
    return hull;
  }
};

// The allowed pairs, honoured in the broad phase (Bullet's filter hook): no narrow phase for them.
struct AllowedFilter final : btOverlapFilterCallback {
  const SceneData* d = nullptr;
  bool needBroadphaseCollision(btBroadphaseProxy* p0, btBroadphaseProxy* p1) const override {
    const auto* a = static_cast<const btCollisionObject*>(p0->m_clientObject);
    const auto* b = static_cast<const btCollisionObject*>(p1->m_clientObject);
    return !d->is_allowed(std::uint32_t(a->getUserIndex()), std::uint32_t(b->getUserIndex()));
  }
};

class BulletEngine final : public Engine {
 public:
  explicit BulletEngine(const SceneData& d)
      : d_(d), dispatcher_(&config_), world_(&dispatcher_, &broadphase_, &config_) {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher_);
    filter_.d = &d;
    world_.getPairCache()->setOverlapFilterCallback(&filter_);
    std::map<const Model*, BulletShape*> shape_of;
    for (const ModelPtr& m : d.distinct) {
      shapes_.push_back(std::make_unique<BulletShape>(m->mesh()));
      shape_of[m.get()] = shapes_.back().get();
    }
    for (std::uint32_t i = 0; i < d.models.size(); ++i) {
      auto o = std::make_unique<btCollisionObject>();
      if (d.shapes[i]) {  // Bullet's primitives, margin 0 where Bullet lets it (sphere and capsule keep theirs as radius)
        primitives_.push_back(std::visit(BulletPrimitive{}, *d.shapes[i]));
        o->setCollisionShape(primitives_.back().get());
      } else {
        o->setCollisionShape(shape_of.at(d.models[i].get())->shape.get());
      }
      o->setCollisionFlags(0);  // not static: static-static pairs are never tested
      o->setUserIndex(int(i));
      o->setWorldTransform(bullet_transform(d.poses[i]));
      world_.addCollisionObject(o.get(), btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter);
      objects_.push_back(std::move(o));
    }
  }
  void place(const std::vector<Pose>& poses) override {
    for (std::uint32_t i = 0; i < objects_.size(); ++i) objects_[i]->setWorldTransform(bullet_transform(poses[i]));
  }
  void reset() override { place(d_.poses); }
  void move(std::size_t f) override {
    for (const auto& [i, p] : d_.frames[f]) objects_[i]->setWorldTransform(bullet_transform(p));
  }
  void check(std::vector<IndexPair>& out) override {
    world_.performDiscreteCollisionDetection();
    const int n = dispatcher_.getNumManifolds();
    for (int k = 0; k < n; ++k) {
      const btPersistentManifold* m = dispatcher_.getManifoldByIndexInternal(k);
      bool touching = false;
      for (int c = 0; c < m->getNumContacts() && !touching; ++c) touching = m->getContactPoint(c).getDistance() <= 0;
      if (!touching) continue;
      auto i = std::uint32_t(m->getBody0()->getUserIndex()), j = std::uint32_t(m->getBody1()->getUserIndex());
      out.emplace_back(std::min(i, j), std::max(i, j));
    }
  }

 private:
  const SceneData& d_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btCollisionWorld world_;
  AllowedFilter filter_;
  std::vector<std::unique_ptr<BulletShape>> shapes_;
  std::vector<std::unique_ptr<btCollisionShape>> primitives_;
  std::vector<std::unique_ptr<btCollisionObject>> objects_;
};

// Whether objects i and j touch at these poses: the pair query of their kinds (model, shape).
bool pair_touches(const SceneData& d, std::uint32_t i, std::uint32_t j, const Pose& pi, const Pose& pj,
                  QueryWorkspace& workspace) {
  if (d.models[i] && d.models[j]) return collide(*d.models[i], pi, *d.models[j], pj, QueryOptions{}, workspace).hit;
  if (d.shapes[i] && d.shapes[j]) return distance(*d.shapes[i], pi, *d.shapes[j], pj).distance == 0.0;
  const bool shape_first = d.shapes[i].has_value();
  const std::uint32_t s = shape_first ? i : j, m = shape_first ? j : i;
  return std::visit([&](const auto& shape) { return collide(shape, shape_first ? pi : pj, *d.models[m], shape_first ? pj : pi).hit; },
                    *d.shapes[s]);
}

// Brute force: the pair query on every object pair that is not allowed; a pair whose bounding
// spheres (a model's: centre of its bounds box, radius the farthest vertex, padded; a shape's:
// around its box) are disjoint cannot touch and is skipped.
PairsPerFrame brute_force(const SceneData& d) {
  const std::size_t n = d.models.size();
  std::map<const Model*, std::pair<Vec3, double>> sphere;
  for (const ModelPtr& m : d.distinct) {
    const Vec3 c = m->bounds().center;
    double r = 0;
    for (const Vec3& v : m->mesh().vertices) r = std::max(r, (v - c).norm());
    sphere[m.get()] = {c, r * (1 + 1e-9) + 1e-12};
  }
  const auto sphere_of = [&](std::size_t i) -> std::pair<Vec3, double> {
    if (d.shapes[i]) return {Vec3::Zero(), bounding_box(*d.shapes[i]).half_extents.norm() * (1 + 1e-9) + 1e-12};
    return sphere.at(d.models[i].get());
  };
  std::vector<Pose> poses = d.poses;
  PairsPerFrame all;
  QueryWorkspace workspace;
  for (std::size_t f = 0; f <= d.frames.size(); ++f) {
    if (f > 0)
      for (const auto& [i, p] : d.frames[f - 1]) poses[i] = p;
    std::vector<Vec3> centre(n);
    std::vector<double> radius(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto [c, r] = sphere_of(i);
      centre[i] = poses[i].rotation * c + poses[i].translation;
      radius[i] = r;
    }
    std::vector<IndexPair> pairs;
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j) {
        if ((centre[i] - centre[j]).norm() > radius[i] + radius[j] || d.is_allowed(i, j)) continue;
        if (pair_touches(d, i, j, poses[i], poses[j], workspace)) pairs.emplace_back(i, j);
      }
    all.push_back(std::move(pairs));
  }
  return all;
}

// One pass over the initial poses and every frame, untimed: the engine's pairs per frame.
PairsPerFrame answers(Engine& e, const SceneData& d) {
  PairsPerFrame all;
  e.reset();
  for (std::size_t f = 0; f <= d.frames.size(); ++f) {
    if (f > 0) e.move(f - 1);
    std::vector<IndexPair> pairs;
    e.check(pairs);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    all.push_back(std::move(pairs));
  }
  return all;
}

std::size_t mismatches(const PairsPerFrame& got, const PairsPerFrame& want) {
  std::size_t count = 0;
  for (std::size_t f = 0; f < want.size(); ++f) {
    std::vector<IndexPair> diff;
    std::set_symmetric_difference(got[f].begin(), got[f].end(), want[f].begin(), want[f].end(),
                                  std::back_inserter(diff));
    count += diff.size();
  }
  return count;
}

// Checks/s over at least `min_seconds` of thread CPU time, in batches that double between clock
// reads: reading the thread CPU clock is a system call (about 2 us here), a third of one check on
// the small scenes. With `move_all`, each check follows a move of every object, alternately to its
// initial pose and to d.stepped: every world box changes, so each engine updates its broad phase
// for every object, and tightbvh's pair cache is made anew. (A move to the pose an object already
// has would not do: tightbvh keeps a box that did not change, as Bullet keeps a proxy whose box
// still fits.)
double checks_per_second(Engine& e, const SceneData& d, bool move_all, double min_seconds,
                         std::vector<IndexPair>& pairs) {
  std::size_t count = 0;
  bool shifted = false;
  const double t0 = thread_seconds();
  double t = 0;
  for (std::size_t batch = 1; t < min_seconds; batch *= 2) {
    for (std::size_t k = 0; k < batch; ++k) {
      if (move_all) {
        shifted = !shifted;
        e.place(shifted ? d.stepped : d.poses);
      }
      pairs.clear();
      e.check(pairs);
    }
    count += batch;
    t = thread_seconds() - t0;
  }
  return double(count) / t;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Without frames, checks/s with every object moved before each check: the median of `reps`.
double rate_all_moved(Engine& e, const SceneData& d, int reps, double min_seconds) {
  std::vector<double> rates;
  std::vector<IndexPair> pairs;
  for (int r = 0; r < reps; ++r) rates.push_back(checks_per_second(e, d, true, min_seconds, pairs));
  return median(rates);
}

// Checks/s of the unchanged scene (no frames) or frames/s, median of `reps` repetitions of
// thread CPU time.
double rate(Engine& e, const SceneData& d, int reps, double min_seconds) {
  std::vector<double> rates;
  std::vector<IndexPair> pairs;
  for (int r = 0; r < reps; ++r) {
    e.reset();
    if (d.frames.empty()) {
      e.check(pairs);  // brings lazily built structures up to date outside the timing
      rates.push_back(checks_per_second(e, d, false, min_seconds, pairs));
    } else {
      pairs.clear();
      e.check(pairs);
      const double t0 = thread_seconds();
      for (std::size_t f = 0; f < d.frames.size(); ++f) {
        e.move(f);
        pairs.clear();
        e.check(pairs);
      }
      rates.push_back(double(d.frames.size()) / (thread_seconds() - t0));
    }
  }
  return median(rates);
}

// The memory of `scene`: its models counted once, the scene layer, and the models counted per object.
nlohmann::json memory_report(const Scene& scene) {
  (void)scene.tree_stats();  // builds the top-level tree, part of own_bytes()
  std::size_t unshared = 0;
  for (const ObjectId id : scene.ids())
    if (scene.object(id).model) unshared += scene.object(id).model->bytes();
  const std::size_t objects = scene.size();
  return {{"objects", objects},
          {"models", scene.model_count()},
          {"model_bytes", scene.model_bytes()},
          {"own_bytes", scene.own_bytes()},
          {"own_bytes_per_object", objects ? double(scene.own_bytes()) / double(objects) : 0.0},
          {"unshared_model_bytes", unshared}};
}

// The broad phase's candidates at the initial poses: tested object pairs whose world boxes overlap.
std::size_t candidate_pairs(const Scene& scene) {
  const std::vector<ObjectId> ids = scene.ids();
  std::vector<Aabb> boxes;
  for (const ObjectId id : ids) boxes.push_back(scene.world_bounds(id));
  std::size_t count = 0;
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (std::size_t j = i + 1; j < ids.size(); ++j)
      count += (boxes[i].min.array() <= boxes[j].max.array()).all() &&
               (boxes[j].min.array() <= boxes[i].max.array()).all() && scene.tested(ids[i], ids[j]);
  return count;
}

// A scene of `count` objects sharing the first `models` distinct models of `d` (see the file comment).
Scene memory_scene(const SceneData& d, std::size_t count, std::size_t models) {
  models = std::min(models, d.distinct.size());
  Scene scene;
  double extent = 1.0;
  for (const Pose& p : d.poses) extent = std::max(extent, p.translation.cwiseAbs().maxCoeff());
  for (std::size_t i = 0; i < count; ++i) {
    Pose pose = d.poses[i % d.poses.size()];
    pose.translation.x() += 3.0 * extent * double(i / d.poses.size());
    scene.add(d.distinct[i % models], pose, "m" + std::to_string(i));
  }
  return scene;
}

int run(int argc, char** argv) {
  CLI::App app{"tightbvh-bench --scene: tightbvh's Scene vs FCL's dynamic AABB tree manager and Bullet's "
               "btCollisionWorld on a scene file"};
  std::string scene_path, json_path;
  int reps = 3;
  double min_seconds = 0.3;
  std::vector<std::string> only;
  app.add_option("--scene", scene_path, "scene file (scene_file.hpp format)")->required();
  app.add_option("--json", json_path, "write the rows as JSON to this file");
  app.add_option("--reps", reps, "repetitions (median)")->check(CLI::PositiveNumber);
  app.add_option("--min-seconds", min_seconds, "without frames: CPU seconds per repetition");
  app.add_option("--engines", only, "subset of: tightbvh fcl fcl-export bullet")->delimiter(',');
  double step = 1e-4;
  app.add_option("--step", step,
                 "without frames: the all-moved checks' step, a fraction of the scene's extent (0: every object "
                 "re-posed where it is)")
      ->check(CLI::NonNegativeNumber);
  std::size_t memory_objects = 0, memory_models = 10;
  app.add_option("--memory-objects", memory_objects, "also report the memory of this many objects sharing models");
  app.add_option("--memory-models", memory_models, "with --memory-objects: how many models they share")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  if (!std::isfinite(step)) throw InputError("--step must be a finite number >= 0, got " + std::to_string(step));

  SceneFile file = load_scene_file(scene_path);
  SceneData d;
  d.ids = file.scene.ids();
  std::map<ObjectId, std::uint32_t> index;
  for (std::uint32_t i = 0; i < d.ids.size(); ++i) {
    const SceneObject& o = file.scene.object(d.ids[i]);
    index[d.ids[i]] = i;
    d.models.push_back(o.model);
    d.shapes.push_back(o.shape);
    d.poses.push_back(o.pose);
    if (o.model && std::find(d.distinct.begin(), d.distinct.end(), o.model) == d.distinct.end())
      d.distinct.push_back(o.model);
  }
  for (std::uint32_t i = 0; i < d.ids.size(); ++i)
    for (std::uint32_t j = i + 1; j < d.ids.size(); ++j)
      if (file.scene.allowed(d.ids[i], d.ids[j])) d.allowed.insert(SceneData::key(i, j));
  for (const SceneFrame& f : file.frames) {
    std::vector<std::pair<std::uint32_t, Pose>> moves;
    for (std::size_t k = 0; k < f.objects.size(); ++k) moves.emplace_back(index.at(f.objects[k]), f.poses[k]);
    d.frames.push_back(std::move(moves));
  }
  // All moved/s: a step of `step` times the scene's extent (the largest coordinate of a pose's
  // translation) along every axis.
  double extent = 0.0;
  for (const Pose& p : d.poses) extent = std::max(extent, p.translation.cwiseAbs().maxCoeff());
  for (Pose p : d.poses) {
    p.translation += Vec3::Constant(step * (extent > 0.0 ? extent : 1.0));
    d.stepped.push_back(p);
  }
  const bool frames = !d.frames.empty();
  std::fprintf(stderr, "%s: %zu objects, %zu models, %zu allowed pairs, %zu frames\n", scene_path.c_str(),
               d.ids.size(), d.distinct.size(), d.allowed.size(), d.frames.size());

  const double b0 = thread_seconds();
  const PairsPerFrame truth = brute_force(d);
  std::size_t touching = 0;
  for (const auto& f : truth) touching += f.size();
  std::fprintf(stderr, "brute force: %zu touching pairs over %zu states (%.1f s)\n", touching, truth.size(),
               thread_seconds() - b0);

  struct Row {
    std::string engine;
    double rate;
    double rate_all_moved;  // without frames only, else 0
    std::size_t mismatches;
    std::size_t touching;
  };
  std::vector<Row> rows;
  const std::vector<std::pair<std::string, std::function<std::unique_ptr<Engine>()>>> engines = {
      {"tightbvh", [&] { return std::make_unique<TightbvhEngine>(d, file.scene); }},
      {"fcl", [&] { return std::make_unique<FclEngine>(d, false); }},
      {"fcl-export", [&] { return std::make_unique<FclEngine>(d, true); }},
      {"bullet", [&] { return std::make_unique<BulletEngine>(d); }},
  };
  for (const auto& [name, make] : engines) {
    if (!only.empty() && std::find(only.begin(), only.end(), name) == only.end()) continue;
    std::unique_ptr<Engine> e = make();
    const PairsPerFrame got = answers(*e, d);
    std::size_t found = 0;
    for (const auto& f : got) found += f.size();
    const std::size_t bad = mismatches(got, truth);
    const double r = rate(*e, d, reps, min_seconds);
    const double moved = frames ? 0.0 : rate_all_moved(*e, d, reps, min_seconds);
    rows.push_back({name, r, moved, bad, found});
    std::fprintf(stderr, "  %s: %.4g %s, %.4g checks/s after moving all, %zu pairs, %zu mismatches\n", name.c_str(),
                 r, frames ? "frames/s" : "checks/s", moved, found, bad);
  }

  auto row_of = [&](const std::string& name) -> const Row* {
    for (const Row& r : rows)
      if (r.engine == name) return &r;
    return nullptr;
  };
  const double fcl = row_of("fcl") ? row_of("fcl")->rate : 0.0, bullet = row_of("bullet") ? row_of("bullet")->rate : 0.0;
  const double fcl_moved = row_of("fcl") ? row_of("fcl")->rate_all_moved : 0.0;
  const double bullet_moved = row_of("bullet") ? row_of("bullet")->rate_all_moved : 0.0;
  const char* unit = frames ? "frames/s" : "checks/s";
  std::printf("%-10s %12s %10s %10s %14s %10s %10s %8s %11s\n", "engine", unit, "vs fcl", "vs bullet", "all moved/s",
              "vs fcl", "vs bullet", "pairs", "mismatches");
  nlohmann::json out = {{"scene", scene_path}, {"objects", d.ids.size()}, {"models", d.distinct.size()},
                        {"frames", d.frames.size()}, {"unit", unit}, {"brute_force_pairs", touching},
                        {"touching_pairs", truth.front().size()}, {"candidate_pairs", candidate_pairs(file.scene)},
                        {"allowed_pairs", d.allowed.size()}, {"reps", reps}, {"min_seconds", min_seconds},
                        {"clock", "thread CPU"},
                        {"rows", nlohmann::json::array()}};
  for (const Row& r : rows) {
    const double moved_vs_fcl = fcl_moved > 0 ? r.rate_all_moved / fcl_moved : 0.0;
    const double moved_vs_bullet = bullet_moved > 0 ? r.rate_all_moved / bullet_moved : 0.0;
    std::printf("%-10s %12.4g %10.3g %10.3g %14.4g %10.3g %10.3g %8zu %11zu\n", r.engine.c_str(), r.rate,
                fcl > 0 ? r.rate / fcl : 0.0, bullet > 0 ? r.rate / bullet : 0.0, r.rate_all_moved, moved_vs_fcl,
                moved_vs_bullet, r.touching, r.mismatches);
    out["rows"].push_back({{"engine", r.engine}, {"rate", r.rate}, {"vs_fcl", fcl > 0 ? r.rate / fcl : 0.0},
                           {"vs_bullet", bullet > 0 ? r.rate / bullet : 0.0}, {"rate_all_moved", r.rate_all_moved},
                           {"all_moved_vs_fcl", moved_vs_fcl}, {"all_moved_vs_bullet", moved_vs_bullet},
                           {"pairs", r.touching}, {"mismatches", r.mismatches}});
  }
  out["memory"] = memory_report(file.scene);
  const auto print_memory = [](const char* what, const nlohmann::json& m) {
    std::printf("memory (%s): %zu objects, %zu models: models %zu bytes (%zu if each object had its own), scene "
                "layer %zu bytes (%.0f per object)\n",
                what, m["objects"].get<std::size_t>(), m["models"].get<std::size_t>(),
                m["model_bytes"].get<std::size_t>(), m["unshared_model_bytes"].get<std::size_t>(),
                m["own_bytes"].get<std::size_t>(), m["own_bytes_per_object"].get<double>());
  };
  print_memory("scene", out["memory"]);
  if (memory_objects > 0 && !d.distinct.empty()) {
    out["memory_shared"] = memory_report(memory_scene(d, memory_objects, memory_models));
    print_memory("shared models", out["memory_shared"]);
  }
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(1) << "\n";
  // Our answers must equal brute force; a peer's mismatches are reported in its row (Bullet's
  // GImpact reports a few contacts at distance <= 0 for pairs that do not touch exactly).
  for (const Row& r : rows)
    if (r.engine == "tightbvh" && r.mismatches != 0) return 1;
  return 0;
}

}  // namespace

int run_scene_bench(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "tightbvh-bench --scene: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace tightbvh::bench
