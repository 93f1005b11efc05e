#pragma once
/// @file
/// Scenes: many posed objects in one broad phase, the narrow phase on the objects' trees.
///
/// A Scene holds objects, each a shared Model (model.hpp) or a primitive Shape (shape.hpp) at a
/// world pose, with Bullet/Jolt-style
/// collision filter bits (an object pair is tested only when each one's group meets the other's
/// mask) and an optional unique name, addressed by a stable ObjectId (ids are never reused, so a
/// removed and re-added object gets a new id). An explicit set of allowed pairs (MoveIt's
/// allowed-collision matrix) lists object pairs that may touch and are never reported.
///
/// Two levels: a top-level tree over the objects' world-space axis-aligned boxes (each model's
/// bounds() box under the object's pose, padded for rounding), then the pair queries on the
/// models' trees (collide(), distance()) for the object pairs whose boxes are close enough. The
/// top-level tree is rebuilt (median splits) when objects were added or removed and refitted
/// when only poses changed, lazily at the next query; a refit that has made the tree twice as
/// loose as the last build (sum of the internal boxes' surface areas) rebuilds it. A box test
/// never drops a pair the pair query would report: the results are those of the pair queries run
/// on every object pair (the tests check it against that brute force).
///
/// Results are sorted by object id (for pairs: by (a, b)) and are identical for any thread
/// count. Object pairs within one scene are reported with a < b; in the other queries `a` is the
/// scene's (or the first scene's) object and the query object is B.
///
/// Thread safety: queries on a scene may run concurrently (the first one after a change updates
/// the top-level tree under a lock); changes (add, remove, set_pose, ...) must not run
/// concurrently with anything else on the same scene.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tightbvh/aabb.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/shape.hpp"

namespace tightbvh {

/// A scene object's stable handle: assigned by Scene::add in increasing order, never reused.
using ObjectId = std::uint32_t;

/// Every collision filter bit set: the default mask (an object meets every group).
inline constexpr std::uint32_t kAllGroups = 0xffffffffu;

/// Largest deviation |R^T R - I| (per entry) a pose's rotation may have; a rotation beyond it,
/// or with determinant < 0, is an InputError.
inline constexpr double kRotationTolerance = 1e-6;

/// One posed object of a scene: a model or a shape (exactly one of the two).
///
/// A shape's pairs use the shape queries (shape.hpp): against a model, QueryResult::pairs holds
/// (0, triangle) with the shape as A, (triangle, 0) with the shape as B; two shapes touch with no
/// pairs. Shapes are solids; QueryOptions::solid and DistanceOptions::solid apply to model pairs
/// only (a shape wholly inside a closed model, touching no triangle, is not reported), and
/// signed_distance and contacts are not available for shape pairs (InputError).
struct SceneObject {
  ModelPtr model;                    ///< the shared mesh and tree (null for a shape)
  Pose pose;                         ///< x_world = pose.rotation * x_model + pose.translation
  std::uint32_t group = 1;           ///< the filter bits this object belongs to
  std::uint32_t mask = kAllGroups;   ///< the groups it may collide with
  std::string name;                  ///< optional; when not empty, unique within the scene
  std::optional<Shape> shape;        ///< a primitive shape instead of a model
};

/// The top-level tree's counters: the measurement hook for comparing update schemes.
struct SceneTreeStats {
  std::size_t objects = 0;      ///< objects in the scene
  std::size_t nodes = 0;        ///< nodes of the top-level tree (2 * objects - 1)
  std::uint64_t rebuilds = 0;   ///< full rebuilds so far
  std::uint64_t refits = 0;     ///< refits (poses changed, structure kept) so far
  double cost = 0.0;            ///< sum of the internal nodes' box surface areas now
  double built_cost = 0.0;      ///< the same right after the last rebuild
  /// Self walks of the whole tree that made the scene's pair cache anew (the first query, a query
  /// after an add or a remove, with another margin, or after many objects moved).
  std::uint64_t pair_walks = 0;
  /// Updates of the pair cache that walked the tree only with the boxes of the objects moved.
  std::uint64_t pair_updates = 0;
};

namespace scene_detail {
struct State;
struct Access;
}  // namespace scene_detail

/// Posed objects sharing models; see the file comment.
class Scene {
 public:
  /// An empty scene.
  Scene();
  ~Scene();
  /// A copy of the objects, filters, names and allowed pairs (the models stay shared).
  Scene(const Scene& other);
  /// Replaces this scene's contents by a copy of `other`'s.
  Scene& operator=(const Scene& other);
  /// Takes `other`'s contents; `other` is left empty.
  Scene(Scene&& other) noexcept;
  /// Takes `other`'s contents; `other` is left empty.
  Scene& operator=(Scene&& other) noexcept;

  /// Adds an object and returns its new id. InputError for an object with neither or both of a
  /// model and a shape, a non-finite pose or a rotation that is not orthonormal
  /// (kRotationTolerance), or a name already in the scene.
  ObjectId add(SceneObject object);
  /// add() with the default filter bits.
  ObjectId add(ModelPtr model, const Pose& pose, std::string name = {});
  /// add() of a shape with the default filter bits.
  ObjectId add(const Shape& shape, const Pose& pose, std::string name = {});
  /// Removes an object (and its allowed pairs). InputError for an id not in the scene.
  void remove(ObjectId id);
  /// Moves an object. InputError for an unknown id or a bad pose (as add()).
  void set_pose(ObjectId id, const Pose& pose);
  /// Moves many objects: ids[i] to poses[i]. Everything is checked before anything moves
  /// (InputError naming the first bad entry, or for spans of different sizes).
  void set_poses(std::span<const ObjectId> ids, std::span<const Pose> poses);
  /// Sets an object's filter bits.
  void set_filter(ObjectId id, std::uint32_t group, std::uint32_t mask);
  /// Marks the pair as allowed to touch: never reported by the scene's own queries.
  void allow(ObjectId a, ObjectId b);
  /// Removes the pair from the allowed pairs (no-op when it is not there).
  void disallow(ObjectId a, ObjectId b);
  /// Whether the pair was allowed (in either order).
  [[nodiscard]] bool allowed(ObjectId a, ObjectId b) const;
  /// Whether the pair is tested: not the same object, filters meet both ways, not allowed.
  [[nodiscard]] bool tested(ObjectId a, ObjectId b) const;

  /// Whether `id` names an object of the scene.
  [[nodiscard]] bool contains(ObjectId id) const;
  /// The object `id` (InputError for an unknown id).
  [[nodiscard]] const SceneObject& object(ObjectId id) const;
  /// The id of the object named `name`, if any.
  [[nodiscard]] std::optional<ObjectId> find(std::string_view name) const;
  /// Every object id, ascending.
  [[nodiscard]] std::vector<ObjectId> ids() const;
  /// The number of objects.
  [[nodiscard]] std::size_t size() const;
  /// The object's world-space box as the top-level tree holds it (padded for rounding).
  [[nodiscard]] Aabb world_bounds(ObjectId id) const;

  /// The number of distinct models the objects share.
  [[nodiscard]] std::size_t model_count() const;
  /// The heap bytes of the distinct models (Model::bytes(), each counted once).
  [[nodiscard]] std::size_t model_bytes() const;
  /// The heap bytes of the scene's own data (objects, index, names, allowed pairs, top tree).
  [[nodiscard]] std::size_t own_bytes() const;
  /// Brings the top-level tree up to date now (queries do it when needed) and returns its counters.
  [[nodiscard]] SceneTreeStats tree_stats() const;

 private:
  friend struct scene_detail::Access;
  std::unique_ptr<scene_detail::State> state_;
};

/// A touching (or within-margin) object pair and the pair query's answer for it.
struct ObjectPairHit {
  ObjectId a = 0;        ///< the object of A (in a scene's own pairs, the lower id)
  ObjectId b = 0;        ///< the object of B
  QueryResult result;    ///< collide(model_a, pose_a, model_b, pose_b, options)
};

/// A scene object touching the query object, and the pair query's answer (query object = B).
struct ObjectHit {
  ObjectId id = 0;       ///< the scene's object (A)
  QueryResult result;    ///< collide(scene object, query object, options)
};

/// An object pair and its distance (the pair query's answer, with points).
struct ObjectPairDistance {
  ObjectId a = 0;           ///< the object of A (in a scene's own pairs, the lower id)
  ObjectId b = 0;           ///< the object of B
  DistanceResult result;    ///< distance(model_a, pose_a, model_b, pose_b, options)
};

/// A scene object and its distance to the query object (query object = B).
struct ObjectDistance {
  ObjectId id = 0;          ///< the scene's object (A)
  DistanceResult result;    ///< distance(scene object, query object, options)
};

/// Every tested object pair of the scene that touches (options.mode: the first triangle pair of
/// each, or all; margin and solid as in collide()). closed_a / closed_b are ignored: each model's
/// own closedness is used. Narrow-phase pair queries on `threads` threads (0: all cores).
[[nodiscard]] std::vector<ObjectPairHit> collide(const Scene& scene, const QueryOptions& options = {},
                                                 unsigned threads = 1);
/// Every scene object touching `model` at `pose` (the query object ignores filters and allowed pairs).
[[nodiscard]] std::vector<ObjectHit> collide(const Scene& scene, const Model& model, const Pose& pose,
                                             const QueryOptions& options = {}, unsigned threads = 1);
/// Every scene object touching `shape` at `pose` (as for a model; the query object is B, so a
/// hit's triangle pairs are (scene object's triangle, 0) against a model and empty against a shape).
[[nodiscard]] std::vector<ObjectHit> collide(const Scene& scene, const Shape& shape, const Pose& pose,
                                             const QueryOptions& options = {}, unsigned threads = 1);
/// Every object pair (one of `a`, one of `b`) that touches and whose filters meet both ways;
/// allowed pairs are per scene and do not apply across scenes. `a` and `b` must be different scenes.
[[nodiscard]] std::vector<ObjectPairHit> collide(const Scene& a, const Scene& b, const QueryOptions& options = {},
                                                 unsigned threads = 1);
/// collide(scene, model, pose) for every pose, spread over `threads` threads (0: all cores);
/// results in pose order, identical for any thread count. InputError for the first bad pose.
[[nodiscard]] std::vector<std::vector<ObjectHit>> collide_batch(const Scene& scene, const Model& model,
                                                                std::span<const Pose> poses,
                                                                const QueryOptions& options = {}, unsigned threads = 0);
/// collide(scene, shape, pose) for every pose, as for a model.
[[nodiscard]] std::vector<std::vector<ObjectHit>> collide_batch(const Scene& scene, const Shape& shape,
                                                                std::span<const Pose> poses,
                                                                const QueryOptions& options = {}, unsigned threads = 0);

/// The closest tested object pair of the scene, with its points (options as for distance();
/// closed_a / closed_b ignored); none when the scene has no tested pair closer than
/// options.upper_bound. Ties: the lowest (a, b).
[[nodiscard]] std::optional<ObjectPairDistance> distance(const Scene& scene, const DistanceOptions& options = {});
/// The scene object closest to `model` at `pose`; ties: the lowest id.
[[nodiscard]] std::optional<ObjectDistance> distance(const Scene& scene, const Model& model, const Pose& pose,
                                                     const DistanceOptions& options = {});
/// The scene object closest to `shape` at `pose`; ties: the lowest id.
[[nodiscard]] std::optional<ObjectDistance> distance(const Scene& scene, const Shape& shape, const Pose& pose,
                                                     const DistanceOptions& options = {});
/// The closest object pair across two different scenes (filters apply, allowed pairs do not).
[[nodiscard]] std::optional<ObjectPairDistance> distance(const Scene& a, const Scene& b,
                                                         const DistanceOptions& options = {});

/// Every tested object pair of the scene closer than `max_distance` (> 0; distance < max_distance,
/// touching pairs included), each with its distance and points; options.upper_bound is replaced
/// by max_distance. Pair queries on `threads` threads (0: all cores).
[[nodiscard]] std::vector<ObjectPairDistance> distance_within(const Scene& scene, double max_distance,
                                                              const DistanceOptions& options = {},
                                                              unsigned threads = 1);
/// Every scene object closer than `max_distance` to `model` at `pose`.
[[nodiscard]] std::vector<ObjectDistance> distance_within(const Scene& scene, const Model& model, const Pose& pose,
                                                          double max_distance, const DistanceOptions& options = {},
                                                          unsigned threads = 1);
/// Every scene object closer than `max_distance` to `shape` at `pose`.
[[nodiscard]] std::vector<ObjectDistance> distance_within(const Scene& scene, const Shape& shape, const Pose& pose,
                                                          double max_distance, const DistanceOptions& options = {},
                                                          unsigned threads = 1);
/// Every object pair across two different scenes closer than `max_distance`.
[[nodiscard]] std::vector<ObjectPairDistance> distance_within(const Scene& a, const Scene& b, double max_distance,
                                                              const DistanceOptions& options = {},
                                                              unsigned threads = 1);

/// The world-space box of `model` at `pose` as the scene uses it: model.bounds() posed, as an
/// axis-aligned box padded by a relative 1e-9 for rounding.
[[nodiscard]] Aabb world_bounds(const Model& model, const Pose& pose);
/// The same for a shape: its bounding_box() posed.
[[nodiscard]] Aabb world_bounds(const Shape& shape, const Pose& pose);

/// Throws InputError "<who>: <what>: ..." unless `pose` is finite with an orthonormal,
/// right-handed rotation (within kRotationTolerance).
void require_valid_pose(const Pose& pose, const std::string& who, const std::string& what);
/// The same check without a message: whether require_valid_pose would accept `pose`. Cheap (no
/// allocation): for per-query checks, with require_valid_pose called for the message on failure.
[[nodiscard]] bool is_valid_pose(const Pose& pose);

}  // namespace tightbvh
