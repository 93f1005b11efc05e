// Scene: posed objects sharing models, a top-level tree over their world boxes (scene.hpp).
#include "tightbvh/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <variant>

#include "../tree/parallel.hpp"
#include "tightbvh/error.hpp"
#include "top_tree.hpp"

namespace tightbvh {

namespace scene_detail {

struct Slot {
  ObjectId id = 0;
  SceneObject object;
  Aabb box;  // world_bounds(model, pose)
};

std::uint64_t pair_key(ObjectId a, ObjectId b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t{a} << 32) | b;
}

// The narrow phase's scratch, kept between a scene's queries: a fresh QueryWorkspace sizes its
// box cache to B's node count (QueryWorkspace::mapped_b), which costs more than the descent of a
// near-miss pair, once per scene query. A query takes a workspace and gives it back; queries
// running at once each get their own.
class WorkspacePool {
 public:
  [[nodiscard]] std::unique_ptr<QueryWorkspace> take() {
    const std::lock_guard lock(mutex_);
    if (free_.empty()) return std::make_unique<QueryWorkspace>();
    std::unique_ptr<QueryWorkspace> workspace = std::move(free_.back());
    free_.pop_back();
    return workspace;
  }
  void give(std::unique_ptr<QueryWorkspace> workspace) {
    const std::lock_guard lock(mutex_);
    free_.push_back(std::move(workspace));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<QueryWorkspace>> free_;
};

// A slot pair of the pair cache: slots (by index) and their objects' ids, a < b.
struct SlotPair {
  std::uint32_t slot_a, slot_b;
  ObjectId a, b;
  friend bool operator<(const SlotPair& x, const SlotPair& y) { return std::pair(x.a, x.b) < std::pair(y.a, y.b); }
};

struct State {
  std::vector<Slot> slots;
  std::unordered_map<ObjectId, std::uint32_t> index;  // id -> slot
  std::unordered_map<std::string, ObjectId> names;
  std::unordered_set<std::uint64_t> allowed;
  ObjectId next_id = 0;

  // The top-level tree and the pair cache: caches brought up to date under `mutex`.
  mutable std::mutex mutex;
  mutable TopTree tree;
  mutable std::vector<Aabb> boxes;  // boxes[slot], as the tree holds them
  mutable bool structure_dirty = false;
  mutable bool poses_dirty = false;
  mutable std::uint64_t rebuilds = 0;
  mutable std::uint64_t refits = 0;
  mutable double built_cost = 0.0;
  // The scene's own close pairs kept between queries, as Bullet's btDbvtBroadphase keeps its
  // overlapping pairs: every slot pair whose boxes are within `pairs_gap`, sorted by ids. An add or
  // a remove drops it; a move marks the slot, and the next query drops the marked slots' pairs and
  // finds them again by walking the tree with each marked box (close_items), or makes the whole
  // list anew by one self walk when that costs less (kIncrementalShare).
  mutable std::vector<SlotPair> pairs;
  mutable double pairs_gap = 0.0;
  mutable bool pairs_valid = false;
  mutable std::vector<std::uint32_t> moved;  // slots marked since the pairs were made
  mutable std::vector<char> is_moved;        // is_moved[slot]
  mutable std::uint64_t pair_walks = 0;
  mutable std::uint64_t pair_updates = 0;
  mutable WorkspacePool workspaces;  // not copied: scratch only

  State() = default;
  State(const State& o)
      : slots(o.slots), index(o.index), names(o.names), allowed(o.allowed), next_id(o.next_id),
        structure_dirty(true), is_moved(o.slots.size(), 0) {}

  [[nodiscard]] const Slot& slot(ObjectId id, const char* who) const {
    const auto it = index.find(id);
    if (it == index.end()) {
      throw InputError(std::string("scene: ") + who + ": no object with id " + std::to_string(id) +
                       (id < next_id ? " (it was removed)" : ""));
    }
    return slots[it->second];
  }
  [[nodiscard]] Slot& slot(ObjectId id, const char* who) {
    return const_cast<Slot&>(static_cast<const State&>(*this).slot(id, who));
  }

  void structure_changed() {
    structure_dirty = true;
    pairs_valid = false;
    moved.clear();
    is_moved.assign(slots.size(), 0);
  }

  // Slot `at`'s new world box, its slot marked as moved. The broad phase sees a pose only through
  // this box: where it is as it was (an object re-posed where it already is), the tree and the
  // pair cache stay as they are, as Bullet's broad phase keeps a proxy whose new box fits its old one.
  void move_box(std::uint32_t at, const Aabb& box) {
    Aabb& old = slots[at].box;
    if (box.min == old.min && box.max == old.max) return;
    old = box;
    poses_dirty = true;
    if (!is_moved[at]) {
      is_moved[at] = 1;
      moved.push_back(at);
    }
  }

  void prepare() const {
    const std::lock_guard lock(mutex);
    prepare_locked();
  }

  void prepare_locked() const {
    if (structure_dirty) {
      boxes.resize(slots.size());
      for (std::size_t i = 0; i < slots.size(); ++i) boxes[i] = slots[i].box;
      rebuild();
    } else if (poses_dirty) {
      for (const std::uint32_t at : moved) boxes[at] = slots[at].box;
      tree.refit(boxes);
      ++refits;
      // A refit keeps the structure of the poses at the last build; once the boxes have drifted
      // so that the tree is twice as loose, rebuilding costs less than the extra box tests.
      if (tree.cost() > 2.0 * built_cost) rebuild();
    }
    structure_dirty = poses_dirty = false;
  }

  void rebuild() const {
    tree.build(boxes);
    built_cost = tree.cost();
    ++rebuilds;
  }

  // One walk per moved box costs as much as a self walk of the whole tree once 10% to 25% of the
  // objects moved, for 100 to 10,000 objects (tightbvh-scene-bench --benchmark_filter=TopLevel;
  // docs/scenes.md, "The top-level tree").
  static constexpr double kIncrementalShare = 0.15;

  // The pair cache for `gap`, up to date. Under `mutex`, after prepare_locked().
  const std::vector<SlotPair>& close_pairs_locked(double gap) const {
    const bool incremental = pairs_valid && gap == pairs_gap &&
                             static_cast<double>(moved.size()) <= kIncrementalShare * static_cast<double>(slots.size());
    if (incremental && moved.empty()) return pairs;
    const auto add = [&](std::uint32_t i, std::uint32_t j) {
      if (slots[i].id > slots[j].id) std::swap(i, j);
      pairs.push_back({i, j, slots[i].id, slots[j].id});
    };
    if (incremental) {
      std::erase_if(pairs, [&](const SlotPair& p) { return is_moved[p.slot_a] || is_moved[p.slot_b]; });
      for (const std::uint32_t m : moved) {
        scene_detail::close_items(tree, boxes[m], gap, [&](std::uint32_t o) {
          if (o != m && (!is_moved[o] || o > m)) add(m, o);  // a pair of two moved slots once
        });
      }
      ++pair_updates;
    } else {
      pairs.clear();
      scene_detail::close_pairs(tree, tree, true, gap, add);
      pairs_gap = gap;
      pairs_valid = true;
      ++pair_walks;
    }
    std::sort(pairs.begin(), pairs.end());
    for (const std::uint32_t m : moved) is_moved[m] = 0;
    moved.clear();
    return pairs;
  }
};

struct Access {
  static const State& state(const Scene& scene) { return *scene.state_; }
};

}  // namespace scene_detail

using scene_detail::Access;
using scene_detail::Slot;
using scene_detail::State;
using scene_detail::TopTree;
using scene_detail::WorkspacePool;

// ------------------------------------------------------------------ poses and boxes

// The checks of require_valid_pose without the message: the hot paths (a scene's set_poses of
// many objects per frame, the model queries) build the message only for a pose that fails.
bool is_valid_pose(const Pose& pose) {
  const Mat3& r = pose.rotation;
  if (!r.allFinite() || !pose.translation.allFinite()) return false;
  // |R^T R - I| entry by entry: the Gram matrix of the columns (symmetric, 6 dot products).
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      if (!(std::abs(r.col(i).dot(r.col(j)) - (i == j ? 1.0 : 0.0)) <= kRotationTolerance)) return false;
  return r.col(0).cross(r.col(1)).dot(r.col(2)) >= 0.0;  // the determinant
}

void require_valid_pose(const Pose& pose, const std::string& who, const std::string& what) {
  if (!pose.rotation.allFinite() || !pose.translation.allFinite())
    throw InputError(who + ": " + what + ": the pose is not finite (NaN or infinity)");
  const double deviation = (pose.rotation.transpose() * pose.rotation - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(deviation <= kRotationTolerance)) {
    std::ostringstream s;
    s << who << ": " << what << ": the rotation is not orthonormal (|R^T R - I| = " << deviation << " > "
      << kRotationTolerance << ")";
    throw InputError(s.str());
  }
  if (pose.rotation.determinant() < 0.0) throw InputError(who + ": " + what + ": the rotation is a reflection (det < 0)");
}

namespace {

// A box of an object's own frame as the scene holds it at `pose`.
Aabb posed_bounds(const Obb& o, const Pose& pose) {
  const Mat3& r = pose.rotation;
  // Written out (the scene computes one per moved object per frame): the center under the pose,
  // and the half extents h_i = sum_j |(R A)_ij| e_j of the box's axes A and half extents e.
  double c[3], h[3], scale = 0.0;
  for (int i = 0; i < 3; ++i) {
    c[i] = r(i, 0) * o.center.x() + r(i, 1) * o.center.y() + r(i, 2) * o.center.z() + pose.translation[i];
    h[i] = 0.0;
    for (int j = 0; j < 3; ++j)
      h[i] += std::abs(r(i, 0) * o.axes(0, j) + r(i, 1) * o.axes(1, j) + r(i, 2) * o.axes(2, j)) * o.half_extents[j];
    scale = std::max({scale, std::abs(c[i]), h[i]});
  }
  // Covers the rounding of this transform and of the pair queries' own (B mapped into A's frame):
  // 1e-9 of the largest coordinate, at least the least normal double.
  const double pad = 1e-9 * 2.0 * scale + std::numeric_limits<double>::min();
  Aabb box;
  for (int i = 0; i < 3; ++i) {
    box.min[i] = c[i] - h[i] - pad;
    box.max[i] = c[i] + h[i] + pad;
  }
  return box;
}

// The world box of a scene object.
Aabb object_bounds(const SceneObject& object, const Pose& pose) {
  return object.shape ? world_bounds(*object.shape, pose) : world_bounds(*object.model, pose);
}

}  // namespace

Aabb world_bounds(const Model& model, const Pose& pose) { return posed_bounds(model.bounds(), pose); }
Aabb world_bounds(const Shape& shape, const Pose& pose) { return posed_bounds(bounding_box(shape), pose); }

namespace {

std::string object_label(ObjectId id, const std::string& name) {
  return "object " + std::to_string(id) + (name.empty() ? std::string() : " ('" + name + "')");
}

unsigned resolve_threads(unsigned threads, std::size_t jobs) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(jobs, 1)));
}

// results[i] = fn(i, workspace) for i in [0, count) on `threads` threads; order independent. One
// thread uses a workspace of `workspaces` (kept between queries); more threads have their own.
template <class Result, class Fn>
std::vector<Result> run_jobs(std::size_t count, unsigned threads, WorkspacePool& workspaces, Fn&& fn) {
  std::vector<Result> results(count);
  if (count == 0) return results;
  threads = resolve_threads(threads, count);
  if (threads == 1) {
    std::unique_ptr<QueryWorkspace> workspace = workspaces.take();
    for (std::size_t i = 0; i < count; ++i) results[i] = fn(i, *workspace);
    workspaces.give(std::move(workspace));  // not on an exception: the next query makes a new one
    return results;
  }
  detail::WorkerPool<QueryWorkspace> pool(threads);
  const std::size_t chunk = std::clamp<std::size_t>(count / (16 * std::size_t{threads}), 1, 64);
  pool.run(count, [&](std::size_t i, QueryWorkspace& workspace) { results[i] = fn(i, workspace); }, chunk);
  return results;
}

bool filters_meet(const SceneObject& a, const SceneObject& b) {
  return (a.group & b.mask) != 0 && (b.group & a.mask) != 0;
}

// An object pair to query: A's slot and B's slot (or the query object), ids for the order.
struct Job {
  ObjectId a = 0;
  ObjectId b = 0;
  const Slot* sa = nullptr;
  const Slot* sb = nullptr;
  friend bool operator<(const Job& x, const Job& y) { return std::pair(x.a, x.b) < std::pair(y.a, y.b); }
};

QueryOptions scene_options(const QueryOptions& options) {
  QueryOptions o = options;
  o.closed_a = o.closed_b = nullptr;  // each model's own (model.hpp)
  return o;
}

DistanceOptions scene_options(const DistanceOptions& options) {
  DistanceOptions o = options;
  o.closed_a = o.closed_b = nullptr;
  return o;
}

void check_margin(double margin) {
  if (!(margin >= 0.0) || !std::isfinite(margin))
    throw InputError("scene collide: margin must be finite and >= 0, got " + std::to_string(margin));
}

void check_max_distance(double d) {
  if (!(d > 0.0)) throw InputError("scene distance_within: max_distance must be > 0, got " + std::to_string(d));
}

// A shape–model pair's two objects, in whichever order the query has them.
struct ShapeModel {
  const SceneObject& shape;
  const SceneObject& model;
  bool shape_is_a;
  ShapeModel(const SceneObject& a, const SceneObject& b)
      : shape(a.shape ? a : b), model(a.shape ? b : a), shape_is_a(a.shape.has_value()) {}
};

// The pair query of two scene objects, whichever kinds they are (scene.hpp, SceneObject).
QueryResult pair_collide(const SceneObject& a, const SceneObject& b, const QueryOptions& options,
                         QueryWorkspace& workspace) {
  // The scene checked both poses when they were set (add, set_pose, set_poses, the query pose).
  if (a.model && b.model) return scene_detail::collide_checked(*a.model, a.pose, *b.model, b.pose, options, workspace);
  if (options.contacts) throw InputError("scene collide: contacts are not available for shapes");
  QueryResult r;
  if (a.shape && b.shape) {
    r.hit = distance(*a.shape, a.pose, *b.shape, b.pose).distance <= options.margin;
    return r;
  }
  const ShapeModel p(a, b);
  QueryOptions o = options;
  o.solid = false;  // shapes are solids already; see SceneObject
  const ShapeQueryResult q = std::visit(
      [&](const auto& s) { return collide(s, p.shape.pose, *p.model.model, p.model.pose, o); }, *p.shape.shape);
  r.hit = q.hit;
  r.stats = q.stats;
  for (const std::uint32_t t : q.triangles) r.pairs.push_back(p.shape_is_a ? TrianglePair{0, t} : TrianglePair{t, 0});
  return r;
}

DistanceResult pair_distance(const SceneObject& a, const SceneObject& b, const DistanceOptions& options,
                             QueryWorkspace& workspace) {
  if (a.model && b.model) return distance(*a.model, a.pose, *b.model, b.pose, options, workspace);
  if (options.signed_distance) throw InputError("scene distance: signed_distance is not available for shapes");
  DistanceResult r;
  if (a.shape && b.shape) {
    const ShapePairDistance d = distance(*a.shape, a.pose, *b.shape, b.pose);
    if (d.distance >= options.upper_bound) {
      r.distance = options.upper_bound;
      r.beyond_upper_bound = true;
      return r;
    }
    r.distance = d.distance;
    r.point_a = d.point_a;
    r.point_b = d.point_b;
  } else {
    const ShapeModel p(a, b);
    DistanceOptions o = options;
    o.solid = false;  // see SceneObject
    const ShapeDistanceResult d = std::visit(
        [&](const auto& s) { return distance(s, p.shape.pose, *p.model.model, p.model.pose, o); }, *p.shape.shape);
    r.distance = d.distance;
    r.beyond_upper_bound = d.beyond_upper_bound;
    r.stats = d.stats;
    if (r.beyond_upper_bound) return r;
    r.pair = p.shape_is_a ? TrianglePair{0, d.triangle} : TrianglePair{d.triangle, 0};
    r.point_a = p.shape_is_a ? d.point_shape : d.point_mesh;
    r.point_b = p.shape_is_a ? d.point_mesh : d.point_shape;
  }
  r.point_a_local = a.pose.inverse().apply(r.point_a);
  r.point_b_local = b.pose.inverse().apply(r.point_b);
  return r;
}

// The tested pairs of one scene whose boxes are within `gap`, sorted by (a, b) with a < b.
std::vector<Job> self_jobs(const State& s, double gap) {
  const std::lock_guard lock(s.mutex);
  s.prepare_locked();
  std::vector<Job> jobs;
  for (const scene_detail::SlotPair& p : s.close_pairs_locked(gap)) {
    const Slot* x = &s.slots[p.slot_a];
    const Slot* y = &s.slots[p.slot_b];
    if (!filters_meet(x->object, y->object) || (!s.allowed.empty() && s.allowed.contains(scene_detail::pair_key(p.a, p.b))))
      continue;
    jobs.push_back({p.a, p.b, x, y});
  }
  return jobs;
}

std::vector<Job> cross_jobs(const State& a, const State& b, double gap) {
  if (&a == &b) throw InputError("scene query: the two scenes are the same scene (query it alone for its own pairs)");
  a.prepare();
  b.prepare();
  std::vector<Job> jobs;
  scene_detail::close_pairs(a.tree, b.tree, false, gap, [&](std::uint32_t i, std::uint32_t j) {
    const Slot* x = &a.slots[i];
    const Slot* y = &b.slots[j];
    if (filters_meet(x->object, y->object)) jobs.push_back({x->id, y->id, x, y});
  });
  std::sort(jobs.begin(), jobs.end());
  return jobs;
}

// The scene objects whose boxes are within `gap` of the query box, sorted by id.
std::vector<Job> single_jobs(const State& s, const Aabb& query, double gap) {
  s.prepare();
  std::vector<Job> jobs;
  scene_detail::close_items(s.tree, query, gap, [&](std::uint32_t i) { jobs.push_back({s.slots[i].id, 0, &s.slots[i], nullptr}); });
  std::sort(jobs.begin(), jobs.end());
  return jobs;
}

std::vector<ObjectPairHit> collide_jobs(const std::vector<Job>& jobs, const QueryOptions& options, unsigned threads,
                                        WorkspacePool& workspaces) {
  const QueryOptions o = scene_options(options);
  auto results = run_jobs<QueryResult>(jobs.size(), threads, workspaces, [&](std::size_t i, QueryWorkspace& workspace) {
    const Job& j = jobs[i];
    return pair_collide(j.sa->object, j.sb->object, o, workspace);
  });
  std::vector<ObjectPairHit> hits;
  for (std::size_t i = 0; i < jobs.size(); ++i)
    if (results[i].hit) hits.push_back({jobs[i].a, jobs[i].b, std::move(results[i])});
  return hits;
}

std::vector<ObjectPairDistance> within_jobs(const std::vector<Job>& jobs, double max_distance,
                                            const DistanceOptions& options, unsigned threads,
                                            WorkspacePool& workspaces) {
  DistanceOptions o = scene_options(options);
  o.upper_bound = max_distance;
  auto results = run_jobs<DistanceResult>(jobs.size(), threads, workspaces, [&](std::size_t i, QueryWorkspace& workspace) {
    const Job& j = jobs[i];
    return pair_distance(j.sa->object, j.sb->object, o, workspace);
  });
  std::vector<ObjectPairDistance> out;
  for (std::size_t i = 0; i < jobs.size(); ++i)
    if (!results[i].beyond_upper_bound) out.push_back({jobs[i].a, jobs[i].b, std::move(results[i])});
  return out;
}

// Best first over the candidate pairs; `accept(i, j, job)` filters a leaf pair into a Job. A pair
// at the same distance as the best so far is still measured (upper bound just above it), so
// that ties go to the lowest (a, b) whatever order the traversal meets them in.
template <class Accept>
std::optional<ObjectPairDistance> nearest(const TopTree& x, const TopTree& y, bool self, const DistanceOptions& options,
                                          Accept&& accept) {
  DistanceOptions o = scene_options(options);
  std::optional<ObjectPairDistance> best;
  double bound = options.upper_bound;
  QueryWorkspace workspace;
  scene_detail::nearest_pairs(x, y, self, bound, [&](std::uint32_t i, std::uint32_t j, double& best_distance) {
    Job job;
    if (!accept(i, j, job)) return;
    o.upper_bound = best ? std::nextafter(best->result.distance, std::numeric_limits<double>::infinity())
                         : options.upper_bound;
    DistanceResult r = pair_distance(job.sa->object, job.sb->object, o, workspace);
    if (r.beyond_upper_bound) return;
    if (!best || r.distance < best->result.distance ||
        (r.distance == best->result.distance && std::pair(job.a, job.b) < std::pair(best->a, best->b))) {
      best = ObjectPairDistance{job.a, job.b, std::move(r)};
      best_distance = best->result.distance;
    }
  });
  return best;
}

// The scene object that stands for the query object of the single-object queries: a model (held
// by a non-owning pointer, for the query's duration) or a shape.
SceneObject query_object(const Model& model, const Pose& pose) {
  SceneObject object;
  object.model = ModelPtr(ModelPtr(), &model);
  object.pose = pose;
  return object;
}
SceneObject query_object(const Shape& shape, const Pose& pose) {
  SceneObject object;
  object.shape = shape;
  object.pose = pose;
  return object;
}

// A one-object stand-in for the query object of the single-object queries.
struct QueryObject {
  Slot slot;
  TopTree tree;
  template <class Q>
  QueryObject(const Q& query, const Pose& pose, const char* who) {
    require_valid_pose(pose, who, "the query pose");
    slot.object = query_object(query, pose);
    slot.box = world_bounds(query, pose);
    tree.build(std::span<const Aabb>(&slot.box, 1));
  }
};

}  // namespace

// ------------------------------------------------------------------ Scene

Scene::Scene() : state_(std::make_unique<State>()) {}
Scene::~Scene() = default;
Scene::Scene(const Scene& other) : state_(std::make_unique<State>(*other.state_)) {}
Scene& Scene::operator=(const Scene& other) {
  if (this != &other) state_ = std::make_unique<State>(*other.state_);
  return *this;
}
Scene::Scene(Scene&& other) noexcept : state_(std::exchange(other.state_, std::make_unique<State>())) {}
Scene& Scene::operator=(Scene&& other) noexcept {
  if (this != &other) state_ = std::exchange(other.state_, std::make_unique<State>());
  return *this;
}

ObjectId Scene::add(SceneObject object) {
  State& s = *state_;
  const ObjectId id = s.next_id;
  const std::string label = object_label(id, object.name);
  if (!object.model && !object.shape) throw InputError("scene: add: " + label + ": neither a model nor a shape (the model is null)");
  if (object.model && object.shape) throw InputError("scene: add: " + label + ": both a model and a shape (an object is one or the other)");
  require_valid_pose(object.pose, "scene: add", label);
  if (!object.name.empty() && s.names.contains(object.name))
    throw InputError("scene: add: duplicate name '" + object.name + "' (object " +
                     std::to_string(s.names.at(object.name)) + " has it)");
  if (id == std::numeric_limits<ObjectId>::max()) throw InputError("scene: add: out of object ids");
  ++s.next_id;
  Slot slot;
  slot.id = id;
  slot.box = object_bounds(object, object.pose);
  slot.object = std::move(object);
  if (!slot.object.name.empty()) s.names.emplace(slot.object.name, id);
  s.index.emplace(id, static_cast<std::uint32_t>(s.slots.size()));
  s.slots.push_back(std::move(slot));
  s.structure_changed();
  return id;
}

ObjectId Scene::add(ModelPtr model, const Pose& pose, std::string name) {
  SceneObject object;
  object.model = std::move(model);
  object.pose = pose;
  object.name = std::move(name);
  return add(std::move(object));
}

ObjectId Scene::add(const Shape& shape, const Pose& pose, std::string name) {
  SceneObject object;
  object.shape = shape;
  object.pose = pose;
  object.name = std::move(name);
  return add(std::move(object));
}

void Scene::remove(ObjectId id) {
  State& s = *state_;
  (void)s.slot(id, "remove");  // InputError for an unknown or removed id
  const std::uint32_t at = s.index.at(id);
  if (!s.slots[at].object.name.empty()) s.names.erase(s.slots[at].object.name);
  std::erase_if(s.allowed, [&](std::uint64_t key) { return (key >> 32) == id || (key & 0xffffffffu) == id; });
  s.index.erase(id);
  if (at + 1 != s.slots.size()) {
    s.slots[at] = std::move(s.slots.back());
    s.index[s.slots[at].id] = at;
  }
  s.slots.pop_back();
  s.structure_changed();
}

void Scene::set_pose(ObjectId id, const Pose& pose) {
  Slot& slot = state_->slot(id, "set_pose");
  require_valid_pose(pose, "scene: set_pose", object_label(id, slot.object.name));
  slot.object.pose = pose;
  state_->move_box(state_->index.at(id), object_bounds(slot.object, pose));
}

void Scene::set_poses(std::span<const ObjectId> ids, std::span<const Pose> poses) {
  if (ids.size() != poses.size())
    throw InputError("scene: set_poses: " + std::to_string(ids.size()) + " ids but " + std::to_string(poses.size()) +
                     " poses");
  // Every entry checked before any is applied; each id looked up once.
  std::vector<std::uint32_t> at(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Slot& slot = state_->slot(ids[i], "set_poses");
    at[i] = static_cast<std::uint32_t>(&slot - state_->slots.data());
    if (!is_valid_pose(poses[i]))
      require_valid_pose(poses[i], "scene: set_poses: entry " + std::to_string(i), object_label(ids[i], slot.object.name));
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    Slot& slot = state_->slots[at[i]];
    slot.object.pose = poses[i];
    state_->move_box(at[i], object_bounds(slot.object, poses[i]));
  }
}

void Scene::set_filter(ObjectId id, std::uint32_t group, std::uint32_t mask) {
  Slot& slot = state_->slot(id, "set_filter");
  slot.object.group = group;
  slot.object.mask = mask;
}

void Scene::allow(ObjectId a, ObjectId b) {
  (void)state_->slot(a, "allow");
  (void)state_->slot(b, "allow");
  if (a == b) throw InputError("scene: allow: an object with itself (" + std::to_string(a) + ")");
  state_->allowed.insert(scene_detail::pair_key(a, b));
}

void Scene::disallow(ObjectId a, ObjectId b) { state_->allowed.erase(scene_detail::pair_key(a, b)); }

bool Scene::allowed(ObjectId a, ObjectId b) const { return state_->allowed.contains(scene_detail::pair_key(a, b)); }

bool Scene::tested(ObjectId a, ObjectId b) const {
  return a != b && filters_meet(object(a), object(b)) && !allowed(a, b);
}

bool Scene::contains(ObjectId id) const { return state_->index.contains(id); }

const SceneObject& Scene::object(ObjectId id) const { return state_->slot(id, "object").object; }

std::optional<ObjectId> Scene::find(std::string_view name) const {
  const auto it = state_->names.find(std::string(name));
  if (it == state_->names.end()) return std::nullopt;
  return it->second;
}

std::vector<ObjectId> Scene::ids() const {
  std::vector<ObjectId> out;
  out.reserve(state_->slots.size());
  for (const Slot& slot : state_->slots) out.push_back(slot.id);
  std::sort(out.begin(), out.end());
  return out;
}

std::size_t Scene::size() const { return state_->slots.size(); }

Aabb Scene::world_bounds(ObjectId id) const { return state_->slot(id, "world_bounds").box; }

std::size_t Scene::model_count() const {
  std::unordered_set<const Model*> models;
  for (const Slot& slot : state_->slots)
    if (slot.object.model) models.insert(slot.object.model.get());
  return models.size();
}

std::size_t Scene::model_bytes() const {
  std::unordered_set<const Model*> models;
  std::size_t bytes = 0;
  for (const Slot& slot : state_->slots)
    if (slot.object.model && models.insert(slot.object.model.get()).second) bytes += slot.object.model->bytes();
  return bytes;
}

std::size_t Scene::own_bytes() const {
  const State& s = *state_;
  std::size_t bytes = s.slots.capacity() * sizeof(Slot) + s.boxes.capacity() * sizeof(Aabb) + s.tree.bytes();
  for (const Slot& slot : s.slots) bytes += slot.object.name.capacity() > 15 ? slot.object.name.capacity() : 0;
  // Hash tables: one node (key, value, next pointer) per entry plus the bucket array.
  bytes += s.index.size() * (sizeof(std::pair<ObjectId, std::uint32_t>) + sizeof(void*)) +
           s.index.bucket_count() * sizeof(void*);
  bytes += s.names.size() * (sizeof(std::pair<std::string, ObjectId>) + sizeof(void*)) +
           s.names.bucket_count() * sizeof(void*);
  bytes += s.allowed.size() * (sizeof(std::uint64_t) + sizeof(void*)) + s.allowed.bucket_count() * sizeof(void*);
  return bytes;
}

SceneTreeStats Scene::tree_stats() const {
  const State& s = *state_;
  s.prepare();
  SceneTreeStats stats;
  stats.objects = s.slots.size();
  stats.nodes = s.tree.nodes().size();
  stats.rebuilds = s.rebuilds;
  stats.refits = s.refits;
  stats.cost = s.tree.cost();
  stats.built_cost = s.built_cost;
  stats.pair_walks = s.pair_walks;
  stats.pair_updates = s.pair_updates;
  return stats;
}

// ------------------------------------------------------------------ queries

std::vector<ObjectPairHit> collide(const Scene& scene, const QueryOptions& options, unsigned threads) {
  check_margin(options.margin);
  const State& s = Access::state(scene);
  return collide_jobs(self_jobs(s, options.margin), options, threads, s.workspaces);
}

namespace {

template <class Q>
std::vector<ObjectHit> collide_single(const Scene& scene, const Q& object, const Pose& pose, const QueryOptions& options,
                                      unsigned threads) {
  check_margin(options.margin);
  const QueryObject query(object, pose, "scene collide");
  std::vector<Job> jobs = single_jobs(Access::state(scene), query.slot.box, options.margin);
  for (Job& j : jobs) j.sb = &query.slot;
  std::vector<ObjectHit> out;
  for (ObjectPairHit& hit : collide_jobs(jobs, options, threads, Access::state(scene).workspaces))
    out.push_back({hit.a, std::move(hit.result)});
  return out;
}

template <class Q>
std::vector<std::vector<ObjectHit>> collide_batch_single(const Scene& scene, const Q& object, std::span<const Pose> poses,
                                                         const QueryOptions& options, unsigned threads) {
  check_margin(options.margin);
  for (std::size_t i = 0; i < poses.size(); ++i)
    if (!is_valid_pose(poses[i])) require_valid_pose(poses[i], "scene collide_batch", "pose " + std::to_string(i));
  const State& s = Access::state(scene);
  s.prepare();
  const QueryOptions o = scene_options(options);
  return run_jobs<std::vector<ObjectHit>>(poses.size(), threads, s.workspaces, [&](std::size_t i, QueryWorkspace& workspace) {
    std::vector<std::uint32_t> slots;
    scene_detail::close_items(s.tree, world_bounds(object, poses[i]), options.margin,
                              [&](std::uint32_t slot) { slots.push_back(slot); });
    std::sort(slots.begin(), slots.end(), [&](std::uint32_t x, std::uint32_t y) { return s.slots[x].id < s.slots[y].id; });
    const SceneObject query = query_object(object, poses[i]);
    std::vector<ObjectHit> hits;
    for (const std::uint32_t slot : slots) {
      QueryResult r = pair_collide(s.slots[slot].object, query, o, workspace);
      if (r.hit) hits.push_back({s.slots[slot].id, std::move(r)});
    }
    return hits;
  });
}

template <class Q>
std::optional<ObjectDistance> distance_single(const Scene& scene, const Q& object, const Pose& pose,
                                              const DistanceOptions& options) {
  const QueryObject query(object, pose, "scene distance");
  const State& s = Access::state(scene);
  s.prepare();
  auto best = nearest(s.tree, query.tree, false, options, [&](std::uint32_t i, std::uint32_t, Job& job) {
    job = {s.slots[i].id, 0, &s.slots[i], &query.slot};
    return true;
  });
  if (!best) return std::nullopt;
  return ObjectDistance{best->a, std::move(best->result)};
}

template <class Q>
std::vector<ObjectDistance> distance_within_single(const Scene& scene, const Q& object, const Pose& pose,
                                                   double max_distance, const DistanceOptions& options, unsigned threads) {
  check_max_distance(max_distance);
  const QueryObject query(object, pose, "scene distance_within");
  std::vector<Job> jobs = single_jobs(Access::state(scene), query.slot.box, max_distance);
  for (Job& j : jobs) j.sb = &query.slot;
  std::vector<ObjectDistance> out;
  for (ObjectPairDistance& d : within_jobs(jobs, max_distance, options, threads, Access::state(scene).workspaces))
    out.push_back({d.a, std::move(d.result)});
  return out;
}

}  // namespace

std::vector<ObjectHit> collide(const Scene& scene, const Model& model, const Pose& pose, const QueryOptions& options,
                               unsigned threads) {
  return collide_single(scene, model, pose, options, threads);
}

std::vector<ObjectHit> collide(const Scene& scene, const Shape& shape, const Pose& pose, const QueryOptions& options,
                               unsigned threads) {
  return collide_single(scene, shape, pose, options, threads);
}

std::vector<ObjectPairHit> collide(const Scene& a, const Scene& b, const QueryOptions& options, unsigned threads) {
  check_margin(options.margin);
  return collide_jobs(cross_jobs(Access::state(a), Access::state(b), options.margin), options, threads,
                      Access::state(a).workspaces);
}

std::vector<std::vector<ObjectHit>> collide_batch(const Scene& scene, const Model& model, std::span<const Pose> poses,
                                                  const QueryOptions& options, unsigned threads) {
  return collide_batch_single(scene, model, poses, options, threads);
}

std::vector<std::vector<ObjectHit>> collide_batch(const Scene& scene, const Shape& shape, std::span<const Pose> poses,
                                                  const QueryOptions& options, unsigned threads) {
  return collide_batch_single(scene, shape, poses, options, threads);
}

std::optional<ObjectPairDistance> distance(const Scene& scene, const DistanceOptions& options) {
  const State& s = Access::state(scene);
  s.prepare();
  return nearest(s.tree, s.tree, true, options, [&](std::uint32_t i, std::uint32_t j, Job& job) {
    const Slot* x = &s.slots[i];
    const Slot* y = &s.slots[j];
    if (x->id > y->id) std::swap(x, y);
    if (!filters_meet(x->object, y->object) || s.allowed.contains(scene_detail::pair_key(x->id, y->id))) return false;
    job = {x->id, y->id, x, y};
    return true;
  });
}

std::optional<ObjectDistance> distance(const Scene& scene, const Model& model, const Pose& pose,
                                       const DistanceOptions& options) {
  return distance_single(scene, model, pose, options);
}

std::optional<ObjectDistance> distance(const Scene& scene, const Shape& shape, const Pose& pose,
                                       const DistanceOptions& options) {
  return distance_single(scene, shape, pose, options);
}

std::optional<ObjectPairDistance> distance(const Scene& a, const Scene& b, const DistanceOptions& options) {
  const State& sa = Access::state(a);
  const State& sb = Access::state(b);
  if (&sa == &sb) throw InputError("scene distance: the two scenes are the same scene (query it alone for its own pairs)");
  sa.prepare();
  sb.prepare();
  return nearest(sa.tree, sb.tree, false, options, [&](std::uint32_t i, std::uint32_t j, Job& job) {
    const Slot* x = &sa.slots[i];
    const Slot* y = &sb.slots[j];
    if (!filters_meet(x->object, y->object)) return false;
    job = {x->id, y->id, x, y};
    return true;
  });
}

std::vector<ObjectPairDistance> distance_within(const Scene& scene, double max_distance,
                                                const DistanceOptions& options, unsigned threads) {
  check_max_distance(max_distance);
  const State& s = Access::state(scene);
  return within_jobs(self_jobs(s, max_distance), max_distance, options, threads, s.workspaces);
}

std::vector<ObjectDistance> distance_within(const Scene& scene, const Model& model, const Pose& pose,
                                            double max_distance, const DistanceOptions& options, unsigned threads) {
  return distance_within_single(scene, model, pose, max_distance, options, threads);
}

std::vector<ObjectDistance> distance_within(const Scene& scene, const Shape& shape, const Pose& pose,
                                            double max_distance, const DistanceOptions& options, unsigned threads) {
  return distance_within_single(scene, shape, pose, max_distance, options, threads);
}

std::vector<ObjectPairDistance> distance_within(const Scene& a, const Scene& b, double max_distance,
                                                const DistanceOptions& options, unsigned threads) {
  check_max_distance(max_distance);
  return within_jobs(cross_jobs(Access::state(a), Access::state(b), max_distance), max_distance, options, threads,
                     Access::state(a).workspaces);
}

}  // namespace tightbvh
