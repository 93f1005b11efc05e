// tightbvh.Model and tightbvh.Scene: the scene layer (model.hpp, scene.hpp) with the method names
// and return shapes of trimesh.collision.CollisionManager, so that a trimesh user switches by
// changing the line that makes the manager. Objects are addressed by name (a str); the scene's
// ObjectIds stay inside.
#include <pybind11/stl.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "state.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/scene.hpp"
#include "tightbvh/serialize.hpp"
#include "tightbvh/shape.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh::python {
namespace {

// The name trimesh gives the query object of in_collision_single and min_distance_single.
constexpr const char* kExternal = "__external";

// The model's mesh as a tightbvh.Mesh that shares the model (no copy; Meshes are immutable).
std::shared_ptr<Mesh> model_mesh(const ModelPtr& model) {
  return {model, const_cast<Mesh*>(&model->mesh())};
}

bool is_path(py::handle object) {
  return py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__");
}

PyModel make_py_model(py::handle source, const std::string& fitter, const std::string& split, py::handle leaf_size,
                      py::handle threads, py::handle grid, py::handle epsilon, bool improve) {
  const BuildOptions options = build_options(fitter, split, leaf_size, threads, grid, epsilon, improve);
  PyModel result{nullptr, to_string(options.fitter)};
  if (is_path(source)) {
    const std::filesystem::path path = py::module_::import("os").attr("fspath")(source).cast<std::string>();
    const py::gil_scoped_release release;
    result.model = make_model(load_mesh(path), options);
    return result;
  }
  const std::shared_ptr<const Mesh> mesh = to_mesh(source, "mesh_or_path");
  const py::gil_scoped_release release;
  result.model = make_model(*mesh, options);
  return result;
}

// State: (the Mesh, the tree format's bytes (serialize.hpp), the fitter name or None); the tree is
// checked against the mesh again on the way in (Model(Mesh, Tree)).
py::object model_state(const PyModel& p) {
  std::vector<std::byte> bytes;
  {
    const py::gil_scoped_release release;
    bytes = serialize(p.model->tree());
  }
  return py::make_tuple(py::cast(model_mesh(p.model)), py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                        p.fitter ? py::object(py::str(*p.fitter)) : py::none());
}

PyModel model_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 3, "Model");
  if (!py::isinstance<Mesh>(f[0])) throw py::type_error("Model.__setstate__: the mesh must be a Mesh");
  if (!py::isinstance<py::bytes>(f[1])) throw py::type_error("Model.__setstate__: the tree must be bytes");
  PyModel result;
  if (!f[2].is_none()) result.fitter = state_string(f[2], "Model.__setstate__: fitter");
  Mesh mesh = f[0].cast<const Mesh&>();
  const std::string bytes = f[1].cast<std::string>();
  const py::gil_scoped_release release;
  Tree tree = deserialize(std::as_bytes(std::span(bytes.data(), bytes.size())), "Model.__setstate__");
  result.model = make_model(std::move(mesh), std::move(tree));  // InputError unless the tree fits the mesh
  return result;
}

// A touching triangle pair of two objects (trimesh's ContactData, without normal and depth).
struct PyContact {
  std::string name_a, name_b;
  std::optional<std::uint32_t> triangle_a, triangle_b;  // none for a shape
  Vec3 point = Vec3::Zero();
};

// The closest points of two objects (trimesh's DistanceData). No triangles when the distance is a
// solid's containment (Scene(solid=True): one object inside the other).
struct PyDistanceData {
  std::string name_a, name_b;
  std::optional<std::uint32_t> triangle_a, triangle_b;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();
  double distance = 0.0;
};

// A triangle of the state, or None.
std::optional<std::uint32_t> state_triangle(py::handle value, const std::string& what) {
  if (value.is_none()) return std::nullopt;
  return static_cast<std::uint32_t>(state_count(value, what, 0xFFFFFFFFu));
}

// State: (name_a, name_b, triangle_a or None, triangle_b or None, point).
py::object contact_state(const PyContact& c) {
  return py::make_tuple(c.name_a, c.name_b, py::cast(c.triangle_a), py::cast(c.triangle_b), vec3_state(c.point));
}

PyContact contact_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 5, "ContactData");
  const std::string what = "ContactData.__setstate__";
  return {state_string(f[0], what + ": name_a"), state_string(f[1], what + ": name_b"),
          state_triangle(f[2], what + ": triangle_a"), state_triangle(f[3], what + ": triangle_b"),
          state_vec3(f[4], what + ": point")};
}

// State: (name_a, name_b, triangle_a or None, triangle_b or None, point_a, point_b, distance).
py::object distance_data_state(const PyDistanceData& d) {
  return py::make_tuple(d.name_a, d.name_b, py::cast(d.triangle_a), py::cast(d.triangle_b), vec3_state(d.point_a), vec3_state(d.point_b),
                        d.distance);
}

PyDistanceData distance_data_from_state(const py::object& state) {
  const py::tuple f = state_tuple(state, 7, "DistanceData");
  const std::string what = "DistanceData.__setstate__";
  return {state_string(f[0], what + ": name_a"),
          state_string(f[1], what + ": name_b"),
          state_triangle(f[2], what + ": triangle_a"),
          state_triangle(f[3], what + ": triangle_b"),
          state_vec3(f[4], what + ": point_a"),
          state_vec3(f[5], what + ": point_b"),
          state_real(f[6], what + ": distance")};
}

py::set name_set(const std::string& a, const std::string& b) {
  py::set s;
  s.add(py::str(a));
  s.add(py::str(b));
  return s;
}

// Of a pair's two values, the one of the object `name` (`of_a` for name_a, `of_b` for name_b), as
// trimesh's index(name) and point(name); KeyError for another name.
template <class T>
[[nodiscard]] T of_name(const std::string& name, const std::string& name_a, const T& of_a, const std::string& name_b,
                        const T& of_b) {
  if (name == name_a) return of_a;
  if (name == name_b) return of_b;
  throw py::key_error(name);
}

// A point where triangle ta of (ma, pa) touches triangle tb of (mb, pb): the closest point of the
// two world-space triangles (they touch, so it lies on both within rounding).
Vec3 contact_point(const Model& ma, const Pose& pa, std::uint32_t ta, const Model& mb, const Pose& pb,
                   std::uint32_t tb) {
  const auto p = ma.mesh().corners(ta);
  const auto q = mb.mesh().corners(tb);
  return tri_tri_distance(pa.apply(p[0]), pa.apply(p[1]), pa.apply(p[2]), pb.apply(q[0]), pb.apply(q[1]),
                          pb.apply(q[2]))
      .point_p;
}

// A point where the shape object `s` touches triangle t of (model, pose): the shape query on that
// one triangle, whose points are then one point of the triangle inside the shape (shape.hpp).
Vec3 shape_contact_point(const SceneObject& s, const Model& model, const Pose& pose, std::uint32_t t) {
  const auto c = model.mesh().corners(t);
  Mesh single;
  single.vertices = {c[0], c[1], c[2]};
  single.triangles = {{0, 1, 2}};
  return std::visit([&](const auto& shape) { return distance_brute_force(shape, s.pose, single, pose).point_mesh; },
                    *s.shape);
}

// trimesh's return shapes: x, (x, names), (x, data) or (x, names, data).
py::object shaped(py::object value, bool return_names, py::object names, bool return_data, py::object data) {
  if (return_names && return_data) return py::make_tuple(value, names, data);
  if (return_names) return py::make_tuple(value, names);
  if (return_data) return py::make_tuple(value, data);
  return value;
}

class PyScene {
 public:
  PyScene(py::handle threads, bool solid) : threads_(thread_count(threads, "threads")), solid_(solid) {}

  ObjectId add_object(py::handle name_object, py::handle mesh, py::handle transform, py::handle group,
                      py::handle mask) {
    const std::string name = object_name(name_object, "add_object: name");
    const Pose pose = to_pose(transform, "transform");
    const std::uint32_t group_bits = filter_bits(group, "add_object: group");
    const std::uint32_t mask_bits = filter_bits(mask, "add_object: mask");
    if (const std::optional<ShapeAt> shape = shape_at(mesh, pose)) {
      if (const auto old = scene_.find(name)) remove(*old);
      return scene_.add(SceneObject{nullptr, shape->pose, group_bits, mask_bits, name, shape->shape});
    }
    const auto [model, key] = object_model(mesh);
    if (key) ++uses_[*key];  // before any removal, so replacing an object by its own mesh keeps the model
    ObjectId id = 0;
    try {
      // As trimesh: an object of the same name is replaced.
      if (const auto old = scene_.find(name)) remove(*old);
      id = scene_.add(SceneObject{model, pose, group_bits, mask_bits, name, std::nullopt});
    } catch (...) {
      if (key) release(*key);
      throw;
    }
    if (key) keys_[id] = *key;
    return id;
  }

  void remove_object(py::handle name) { remove(id_of(name, "remove_object")); }

  void set_transform(py::handle name, py::handle transform) {
    const ObjectId id = id_of(name, "set_transform");
    scene_.set_pose(id, to_pose(transform, "transform"));
  }

  void set_transforms(const py::sequence& names, py::handle transforms) {
    std::vector<Pose> poses = to_poses(transforms, "transforms");
    if (poses.size() != names.size())
      throw py::value_error("set_transforms: " + std::to_string(names.size()) + " names but " +
                            std::to_string(poses.size()) + " transforms");
    std::vector<ObjectId> ids;
    ids.reserve(names.size());
    for (const py::handle name : names) ids.push_back(id_of(name, "set_transforms"));
    scene_.set_poses(ids, poses);
  }

  void allow(py::handle a, py::handle b, bool allowed) {
    const ObjectId ia = id_of(a, allowed ? "allow" : "disallow");
    const ObjectId ib = id_of(b, allowed ? "allow" : "disallow");
    if (ia == ib) throw py::value_error(std::string(allowed ? "allow" : "disallow") + ": the same object twice");
    const std::string na = scene_.object(ia).name, nb = scene_.object(ib).name;
    if (allowed) {
      scene_.allow(ia, ib);
      allowed_.insert(std::minmax(na, nb));
    } else {
      scene_.disallow(ia, ib);
      allowed_.erase(std::minmax(na, nb));
    }
  }

  void set_filter(py::handle name, py::handle group, py::handle mask) {
    const ObjectId id = id_of(name, "set_filter");
    scene_.set_filter(id, filter_bits(group, "set_filter: group"), filter_bits(mask, "set_filter: mask"));
  }

  py::tuple filter(py::handle name) const {
    const SceneObject& o = scene_.object(id_of(name, "filter"));
    return py::make_tuple(o.group, o.mask);
  }

  bool is_allowed(py::handle a, py::handle b) const {
    return scene_.allowed(id_of(a, "allowed"), id_of(b, "allowed"));
  }

  py::object in_collision_internal(bool return_names, bool return_data) const {
    std::vector<ObjectPairHit> hits;
    {
      const py::gil_scoped_release release;
      hits = collide(scene_, options(return_data), threads_);
    }
    if (!return_names && !return_data) return py::bool_(!hits.empty());  // trimesh's default: no names built
    py::set names;
    py::list data;
    for (const ObjectPairHit& hit : hits) {
      const SceneObject& a = scene_.object(hit.a);
      const SceneObject& b = scene_.object(hit.b);
      if (return_names)
        names.add(a.name < b.name ? py::make_tuple(a.name, b.name) : py::make_tuple(b.name, a.name));
      if (return_data) add_contacts(data, a, a.name, b, b.name, hit.result);
    }
    return shaped(py::bool_(!hits.empty()), return_names, names, return_data, data);
  }

  py::object in_collision_single(py::handle mesh, py::handle transform, bool return_names, bool return_data) {
    const SceneObject query = query_object(mesh, transform);
    std::vector<ObjectHit> hits;
    {
      const py::gil_scoped_release release;
      hits = query.shape ? collide(scene_, *query.shape, query.pose, options(return_data), threads_)
                         : collide(scene_, *query.model, query.pose, options(return_data), threads_);
    }
    if (!return_names && !return_data) return py::bool_(!hits.empty());
    py::set names;
    py::list data;
    for (const ObjectHit& hit : hits) {
      const SceneObject& a = scene_.object(hit.id);
      if (return_names) names.add(py::str(a.name));
      if (return_data) add_contacts(data, a, a.name, query, kExternal, hit.result);
    }
    return shaped(py::bool_(!hits.empty()), return_names, names, return_data, data);
  }

  py::object in_collision_other(const PyScene& other, bool return_names, bool return_data) const {
    if (&other == this) throw py::value_error("in_collision_other: other_manager must be another Scene");
    std::vector<ObjectPairHit> hits;
    {
      const py::gil_scoped_release release;
      hits = collide(scene_, other.scene_, options(return_data), threads_);
    }
    if (!return_names && !return_data) return py::bool_(!hits.empty());
    py::set names;
    py::list data;
    for (const ObjectPairHit& hit : hits) {
      const SceneObject& a = scene_.object(hit.a);
      const SceneObject& b = other.scene_.object(hit.b);
      if (return_names) names.add(py::make_tuple(a.name, b.name));
      if (return_data) add_contacts(data, a, a.name, b, b.name, hit.result);
    }
    return shaped(py::bool_(!hits.empty()), return_names, names, return_data, data);
  }

  py::object min_distance_internal(bool return_names, bool return_data) const {
    std::optional<ObjectPairDistance> d;
    {
      const py::gil_scoped_release release;
      d = distance(scene_, distance_options());
    }
    if (!d) return shaped(py::float_(inf()), return_names, py::none(), return_data, py::none());
    const SceneObject& a = scene_.object(d->a);
    const SceneObject& b = scene_.object(d->b);
    const py::object names = a.name < b.name ? py::make_tuple(a.name, b.name) : py::make_tuple(b.name, a.name);
    return shaped(py::float_(d->result.distance), return_names, names, return_data,
                  distance_data(a.name, b.name, d->result, a.shape.has_value(), b.shape.has_value()));
  }

  py::object min_distance_single(py::handle mesh, py::handle transform, bool return_name, bool return_data) {
    const SceneObject query = query_object(mesh, transform);
    std::optional<ObjectDistance> d;
    {
      const py::gil_scoped_release release;
      d = query.shape ? distance(scene_, *query.shape, query.pose, distance_options())
                      : distance(scene_, *query.model, query.pose, distance_options());
    }
    if (!d) return shaped(py::float_(inf()), return_name, py::none(), return_data, py::none());
    const std::string& name = scene_.object(d->id).name;
    return shaped(py::float_(d->result.distance), return_name, py::str(name), return_data,
                  distance_data(name, kExternal, d->result, scene_.object(d->id).shape.has_value(), query.shape.has_value()));
  }

  py::object min_distance_other(const PyScene& other, bool return_names, bool return_data) const {
    if (&other == this) throw py::value_error("min_distance_other: other_manager must be another Scene");
    std::optional<ObjectPairDistance> d;
    {
      const py::gil_scoped_release release;
      d = distance(scene_, other.scene_, distance_options());
    }
    if (!d) return shaped(py::float_(inf()), return_names, py::none(), return_data, py::none());
    const std::string& a = scene_.object(d->a).name;
    const std::string& b = other.scene_.object(d->b).name;
    return shaped(py::float_(d->result.distance), return_names, py::make_tuple(a, b), return_data,
                  distance_data(a, b, d->result, scene_.object(d->a).shape.has_value(),
                                 other.scene_.object(d->b).shape.has_value()));
  }

  // Every pair closer than max_distance: {key: distance}, with return_data also {key: DistanceData};
  // the keys are the names of min_distance_internal (a sorted name pair), in object id order.
  py::object distance_within_internal(double max_distance, bool return_data) const {
    std::vector<ObjectPairDistance> found;
    {
      const py::gil_scoped_release release;
      found = distance_within(scene_, max_distance, distance_options(), threads_);
    }
    py::dict distances, data;
    for (const ObjectPairDistance& d : found) {
      const std::string& a = scene_.object(d.a).name;
      const std::string& b = scene_.object(d.b).name;
      const py::tuple key = a < b ? py::make_tuple(a, b) : py::make_tuple(b, a);
      distances[key] = d.result.distance;
      if (return_data) data[key] = distance_data(a, b, d.result, scene_.object(d.a).shape.has_value(),
                                                         scene_.object(d.b).shape.has_value());
    }
    return return_data ? py::object(py::make_tuple(distances, data)) : py::object(distances);
  }

  // The same for one query object: keyed by the scene object's name.
  py::object distance_within_single(py::handle mesh, double max_distance, py::handle transform, bool return_data) {
    const SceneObject query = query_object(mesh, transform);
    std::vector<ObjectDistance> found;
    {
      const py::gil_scoped_release release;
      found = query.shape ? distance_within(scene_, *query.shape, query.pose, max_distance, distance_options(), threads_)
                          : distance_within(scene_, *query.model, query.pose, max_distance, distance_options(), threads_);
    }
    py::dict distances, data;
    for (const ObjectDistance& d : found) {
      const std::string& name = scene_.object(d.id).name;
      distances[py::str(name)] = d.result.distance;
      if (return_data)
        data[py::str(name)] = distance_data(name, kExternal, d.result, scene_.object(d.id).shape.has_value(),
                                            query.shape.has_value());
    }
    return return_data ? py::object(py::make_tuple(distances, data)) : py::object(distances);
  }

  // The same across two scenes: keyed by (name here, name there).
  py::object distance_within_other(const PyScene& other, double max_distance, bool return_data) const {
    if (&other == this) throw py::value_error("distance_within_other: other_manager must be another Scene");
    std::vector<ObjectPairDistance> found;
    {
      const py::gil_scoped_release release;
      found = distance_within(scene_, other.scene_, max_distance, distance_options(), threads_);
    }
    py::dict distances, data;
    for (const ObjectPairDistance& d : found) {
      const std::string& a = scene_.object(d.a).name;
      const std::string& b = other.scene_.object(d.b).name;
      const py::tuple key = py::make_tuple(a, b);
      distances[key] = d.result.distance;
      if (return_data) data[key] = distance_data(a, b, d.result, scene_.object(d.a).shape.has_value(),
                                                         other.scene_.object(d.b).shape.has_value());
    }
    return return_data ? py::object(py::make_tuple(distances, data)) : py::object(distances);
  }

  // One in_collision_single per transform, on all of the scene's threads; the names per pose.
  py::list in_collision_batch(py::handle mesh, py::handle transforms) {
    std::vector<Pose> poses = to_poses(transforms, "transforms");
    std::optional<Shape> shape;
    ModelPtr model;
    if (const std::optional<ShapeAt> probe = shape_at(mesh, Pose{})) {
      shape = probe->shape;
      // A fitted Box carries its own pose: each transform is composed with it, as add_object does.
      for (Pose& pose : poses) pose = shape_at(mesh, pose)->pose;
    } else {
      model = query_model(mesh);
    }
    std::vector<std::vector<ObjectHit>> hits;
    {
      const py::gil_scoped_release release;
      hits = shape ? collide_batch(scene_, *shape, poses, options(false), threads_)
                   : collide_batch(scene_, *model, poses, options(false), threads_);
    }
    py::list result;
    for (const std::vector<ObjectHit>& per_pose : hits) {
      py::set names;
      for (const ObjectHit& hit : per_pose) names.add(py::str(scene_.object(hit.id).name));
      result.append(names);
    }
    return result;
  }

  py::list names() const {
    py::list result;
    for (const ObjectId id : scene_.ids()) result.append(py::str(scene_.object(id).name));
    return result;
  }

  bool contains(py::handle name) const {
    return py::isinstance<py::str>(name) && scene_.find(name.cast<std::string>()).has_value();
  }

  py::array_t<double> transform(py::handle name) const {
    const Pose& pose = scene_.object(id_of(name, "transform")).pose;
    py::array_t<double> m({4, 4});
    auto v = m.mutable_unchecked<2>();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) v(r, c) = r < 3 ? (c < 3 ? pose.rotation(r, c) : pose.translation[r]) : (c == 3);
    return m;
  }

  PyModel model(py::handle name) const {
    const SceneObject& o = scene_.object(id_of(name, "model"));
    if (!o.model) throw py::value_error("model: '" + o.name + "' is a shape, not a model");
    return {o.model, std::nullopt};
  }

  // State: (threads, solid, objects: ((name, Model or shape, 4x4 transform, group, mask), ...) in id order,
  // allowed: ((name, name), ...)); an object of 3 fields has the default filter bits. A model
  // shared by objects is one Python object in the state, so it stays shared. The mesh cache is not part of it: after unpickling, adding an original mesh
  // object again builds its model again.
  py::object state() const {
    std::unordered_map<const Model*, py::object> models;
    py::list objects;
    for (const ObjectId id : scene_.ids()) {
      const SceneObject& o = scene_.object(id);
      if (o.shape) {  // the shape itself in place of the model
        const py::object shape = std::visit([](const auto& s) { return py::cast(s); }, *o.shape);
        objects.append(py::make_tuple(o.name, shape, transform(py::str(o.name)), o.group, o.mask));
        continue;
      }
      auto [it, added] = models.try_emplace(o.model.get());
      if (added) it->second = py::cast(PyModel{o.model, std::nullopt});
      objects.append(py::make_tuple(o.name, it->second, transform(py::str(o.name)), o.group, o.mask));
    }
    py::list allowed;
    for (const auto& [a, b] : allowed_) allowed.append(py::make_tuple(a, b));
    return py::make_tuple(threads_, solid_, py::tuple(objects), py::tuple(allowed));
  }

  static PyScene from_state(const py::object& state) {
    const py::tuple f = state_tuple(state, 4, "Scene");
    const std::string what = "Scene.__setstate__";
    PyScene result(f[0], state_bool(f[1], what + ": solid"));
    if (!py::isinstance<py::tuple>(f[2]) || !py::isinstance<py::tuple>(f[3]))
      throw py::type_error(what + ": objects and allowed must be tuples");
    for (const py::handle object : py::reinterpret_borrow<py::tuple>(f[2])) {
      const bool filtered = py::isinstance<py::tuple>(object) && py::len(object) == 5;
      const py::tuple o = state_tuple(object, filtered ? 5 : 3, "Scene object");
      const std::string name = state_string(o[0], what + ": name");
      const Pose pose = to_pose(o[2], what + ": '" + name + "': transform");
      const bool is_model = py::isinstance<PyModel>(o[1]);
      const bool is_shape = py::isinstance<Sphere>(o[1]) || py::isinstance<Box>(o[1]) || py::isinstance<Capsule>(o[1]) ||
                            py::isinstance<Cylinder>(o[1]) || py::isinstance<Convex>(o[1]);
      if (!is_model && !is_shape)
        throw py::type_error(what + ": '" + name + "': the model must be a Model or a tightbvh.shapes shape");
      if (result.scene_.find(name)) throw py::value_error(what + ": duplicate name '" + name + "'");
      SceneObject added{is_model ? o[1].cast<const PyModel&>().model : nullptr, pose, 1, kAllGroups, name, std::nullopt};
      if (is_shape) added.shape = shape_at(o[1], pose)->shape;
      if (filtered) {
        added.group = static_cast<std::uint32_t>(state_count(o[3], what + ": '" + name + "': group", kAllGroups));
        added.mask = static_cast<std::uint32_t>(state_count(o[4], what + ": '" + name + "': mask", kAllGroups));
      }
      result.scene_.add(std::move(added));
    }
    for (const py::handle pair : py::reinterpret_borrow<py::tuple>(f[3])) {
      const py::tuple p = state_tuple(pair, 2, "Scene allowed pair");
      result.allow(p[0], p[1], true);
    }
    return result;
  }

  std::size_t size() const { return scene_.size(); }
  std::size_t model_count() const { return scene_.model_count(); }
  std::size_t model_bytes() const { return scene_.model_bytes(); }
  unsigned threads() const { return threads_; }
  bool solid() const { return solid_; }

 private:
  static double inf() { return std::numeric_limits<double>::infinity(); }

  QueryOptions options(bool all_pairs) const {
    QueryOptions o;
    o.mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit;
    o.solid = solid_;
    return o;
  }

  DistanceOptions distance_options() const {
    DistanceOptions o;
    o.solid = solid_;
    return o;
  }

  // Collision filter bits: an int in [0, 2**32) (TypeError for another type, ValueError out of range).
  static std::uint32_t filter_bits(py::handle value, const std::string& what) {
    if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
      throw py::type_error(what + ": expected an int, got " + py::str(py::type::of(value)).cast<std::string>());
    if (py::int_(0).attr("__gt__")(value).cast<bool>() || py::int_(kAllGroups).attr("__lt__")(value).cast<bool>())
      throw py::value_error(what + ": must be in [0, 2**32), got " + py::str(value).cast<std::string>());
    return value.cast<std::uint32_t>();
  }

  static std::string object_name(py::handle name, const std::string& what) {
    if (!py::isinstance<py::str>(name))
      throw py::type_error(what + ": expected a str, got " + py::str(py::type::of(name)).cast<std::string>());
    return name.cast<std::string>();
  }

  ObjectId id_of(py::handle name_object, const std::string& what) const {
    const std::string name = object_name(name_object, what + ": name");
    const auto id = scene_.find(name);
    if (!id) throw py::value_error(what + ": '" + name + "' not in the scene");
    return *id;
  }

  void remove(ObjectId id) {
    const std::string name = scene_.object(id).name;
    scene_.remove(id);
    std::erase_if(allowed_, [&](const auto& pair) { return pair.first == name || pair.second == name; });
    const auto key = keys_.find(id);
    if (key == keys_.end()) return;
    release(key->second);
    keys_.erase(key);
  }

  // One object less uses the cache entry `key`; the last one drops it.
  void release(std::uintptr_t key) {
    if (--uses_[key] > 0) return;
    uses_.erase(key);
    cache_.attr("pop")(py::int_(key), py::none());
  }

  // The model of an object's mesh, and the cache key when it came from (or went into) the cache:
  // a tightbvh.Model is used as it is; any other mesh object is built once per Python object
  // (keyed by id(), the object kept alive so the id stays its own) while an object uses it.
  std::pair<ModelPtr, std::optional<std::uintptr_t>> object_model(py::handle mesh) {
    if (py::isinstance<PyModel>(mesh)) return {mesh.cast<const PyModel&>().model, std::nullopt};
    const auto key = reinterpret_cast<std::uintptr_t>(mesh.ptr());
    if (cache_.contains(py::int_(key)))
      return {cache_[py::int_(key)].cast<py::tuple>()[1].cast<const PyModel&>().model, key};
    const py::object query = query_cache_.attr("pop")(py::int_(key), py::none());
    ModelPtr model = query.is_none() ? build(mesh) : query.cast<py::tuple>()[1].cast<const PyModel&>().model;
    cache_[py::int_(key)] = py::make_tuple(mesh, py::cast(PyModel{model, std::nullopt}));
    return {std::move(model), key};
  }

  // The model of a query mesh: an object's model when the same Python object was added, else
  // built once and kept in a small cache (the last kQueryCache query meshes).
  // The query object of the *_single calls: a shape (tightbvh.shapes, or a fitted Box) at the
  // transform, or a mesh's model (cached as query_model says).
  SceneObject query_object(py::handle mesh, py::handle transform) {
    const Pose pose = to_pose(transform, "transform");
    if (const std::optional<ShapeAt> shape = shape_at(mesh, pose))
      return SceneObject{nullptr, shape->pose, 1, kAllGroups, kExternal, shape->shape};
    return SceneObject{query_model(mesh), pose, 1, kAllGroups, kExternal, std::nullopt};
  }

  ModelPtr query_model(py::handle mesh) {
    if (py::isinstance<PyModel>(mesh)) return mesh.cast<const PyModel&>().model;
    const py::int_ key(reinterpret_cast<std::uintptr_t>(mesh.ptr()));
    if (cache_.contains(key)) return cache_[key].cast<py::tuple>()[1].cast<const PyModel&>().model;
    if (query_cache_.contains(key)) return query_cache_[key].cast<py::tuple>()[1].cast<const PyModel&>().model;
    ModelPtr model = build(mesh);
    if (py::len(query_cache_) >= kQueryCache) query_cache_.attr("clear")();
    query_cache_[key] = py::make_tuple(mesh, py::cast(PyModel{model, std::nullopt}));
    return model;
  }

  static ModelPtr build(py::handle mesh) {
    const std::shared_ptr<const Mesh> converted = to_mesh(mesh, "mesh");
    const py::gil_scoped_release release;
    return make_model(*converted);
  }

  static void add_contacts(py::list& data, const SceneObject& a, const std::string& name_a, const SceneObject& b,
                           const std::string& name_b, const QueryResult& result) {
    if (a.shape && b.shape) {  // no triangles: one point of both shapes
      data.append(PyContact{name_a, name_b, std::nullopt, std::nullopt,
                            distance(*a.shape, a.pose, *b.shape, b.pose).point_a});
      return;
    }
    for (const TrianglePair& pair : result.pairs) {
      if (a.model && b.model) {
        data.append(PyContact{name_a, name_b, pair.a, pair.b,
                              contact_point(*a.model, a.pose, pair.a, *b.model, b.pose, pair.b)});
      } else if (a.shape) {
        data.append(PyContact{name_a, name_b, std::nullopt, pair.b, shape_contact_point(a, *b.model, b.pose, pair.b)});
      } else {
        data.append(PyContact{name_a, name_b, pair.a, std::nullopt, shape_contact_point(b, *a.model, a.pose, pair.a)});
      }
    }
  }

  // A shape's side has no triangle (None).
  static py::object distance_data(const std::string& a, const std::string& b, const DistanceResult& r, bool shape_a,
                                  bool shape_b) {
    PyDistanceData d{a, b, std::nullopt, std::nullopt, r.point_a, r.point_b, r.distance};
    if (r.inside == Inside::none) {
      if (!shape_a) d.triangle_a = r.pair.a;
      if (!shape_b) d.triangle_b = r.pair.b;
    }
    return py::cast(std::move(d));
  }

  static constexpr std::size_t kQueryCache = 16;

  Scene scene_;
  unsigned threads_ = 1;
  bool solid_ = false;
  py::dict cache_;        // id(mesh) -> (mesh, Model) for the meshes of the objects
  py::dict query_cache_;  // the same for query meshes (in_collision_single, ...)
  std::unordered_map<ObjectId, std::uintptr_t> keys_;  // object -> its mesh's cache key
  std::unordered_map<std::uintptr_t, std::size_t> uses_;  // cache key -> objects using it
  std::set<std::pair<std::string, std::string>> allowed_;  // the allowed pairs by name, each sorted
};

}  // namespace

void bind_scene(py::module_& m) {
  const BuildOptions defaults;
  py::class_<PyModel>(m, "Model",
                      "A mesh and its tree, built once and shared by any number of scene objects (model.hpp). "
                      "Immutable.")
      .def(py::init(&make_py_model), py::arg("mesh_or_path"), py::arg("fitter") = to_string(defaults.fitter),
           py::arg("split") = std::string(to_string(defaults.split)), py::arg("leaf_size") = defaults.leaf_size,
           py::arg("threads") = defaults.threads, py::arg("grid") = py::none(), py::arg("epsilon") = py::none(),
           py::arg("improve") = defaults.fit.improve,
           "From a mesh (a Mesh or anything with .vertices and .faces) or a mesh file's path; the keyword "
           "arguments are those of tightbvh.build.")
      .def_property_readonly(
          "mesh", [](const PyModel& p) { return model_mesh(p.model); }, "the Mesh (shared with the model, not a copy)")
      .def_property_readonly(
          "tree", [](const PyModel& p) { return PyTree{p.model->tree(), model_mesh(p.model), std::nullopt, p.fitter}; },
          "a Tree: a copy of the model's tree, with the model's mesh")
      .def_readonly("fitter", &PyModel::fitter, "the fitter it was built with (None when not known)")
      .def_property_readonly("triangle_count", [](const PyModel& p) { return p.model->mesh().triangles.size(); })
      .def_property_readonly("node_count", [](const PyModel& p) { return p.model->tree().nodes.size(); })
      .def_property_readonly(
          "bytes", [](const PyModel& p) { return p.model->bytes(); },
          "heap bytes held: vertices, triangles, tree nodes and order, closedness")
      .def("__eq__", [](const PyModel& a, const PyModel& b) { return a.model == b.model; },
           "the same model (not merely equal meshes)")
      .def("__hash__", [](const PyModel& p) { return std::hash<const Model*>{}(p.model.get()); })
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&model_state, &model_from_state))
      .def("__repr__", [](const PyModel& p) {
        return "<tightbvh.Model: " + std::to_string(p.model->mesh().triangles.size()) + " triangles, " +
               std::to_string(p.model->tree().nodes.size()) + " nodes>";
      });

  py::class_<PyContact>(m, "ContactData",
                        "A touching triangle pair of two objects, as trimesh's ContactData without normal and "
                        "depth: names, point, index(name), and triangles (of the first name, of the second).")
      .def_property_readonly("names", [](const PyContact& c) { return name_set(c.name_a, c.name_b); })
      .def_property_readonly("point", [](const PyContact& c) { return to_array(c.point); },
                             "a world point where the two triangles touch")
      .def_property_readonly("triangles",
                             [](const PyContact& c) { return py::make_tuple(py::cast(c.triangle_a), py::cast(c.triangle_b)); })
      .def(
          "index",
          [](const PyContact& c, const std::string& name) {
            return of_name(name, c.name_a, c.triangle_a, c.name_b, c.triangle_b);
          },
          py::arg("name"), "the touching triangle of the object `name` (None for a shape)")
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&contact_state, &contact_from_state))
      .def("__repr__", [](const PyContact& c) {
        const auto index = [](const std::optional<std::uint32_t>& t) { return t ? std::to_string(*t) : "shape"; };
        return "<tightbvh.ContactData " + c.name_a + "[" + index(c.triangle_a) + "] " + c.name_b + "[" +
               index(c.triangle_b) + "]>";
      });

  py::class_<PyDistanceData>(m, "DistanceData",
                             "The closest points of two objects, as trimesh's DistanceData: names, distance, "
                             "index(name), point(name).")
      .def_property_readonly("names", [](const PyDistanceData& d) { return name_set(d.name_a, d.name_b); })
      .def_readonly("distance", &PyDistanceData::distance)
      .def(
          "index",
          [](const PyDistanceData& d, const std::string& name) {
            return of_name(name, d.name_a, d.triangle_a, d.name_b, d.triangle_b);
          },
          py::arg("name"), "the closest triangle of the object `name` (None for a solid's containment)")
      .def(
          "point",
          [](const PyDistanceData& d, const std::string& name) {
            return to_array(of_name(name, d.name_a, d.point_a, d.name_b, d.point_b));
          },
          py::arg("name"), "the closest point (world frame) on the object `name`")
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle(&distance_data_state, &distance_data_from_state))
      .def("__repr__", [](const PyDistanceData& d) {
        return "<tightbvh.DistanceData " + d.name_a + " " + d.name_b + " distance=" + std::to_string(d.distance) + ">";
      });

  py::class_<PyScene>(m, "Scene",
                      "Named posed meshes in one broad phase (scene.hpp), with the methods of "
                      "trimesh.collision.CollisionManager. A mesh object added twice is built once (one Model). "
                      "Do not change a scene while another thread queries it. Pickles and copies (models stay "
                      "shared within the copy).")
      .def(py::init<py::handle, bool>(), py::arg("threads") = 1, py::arg("solid") = false,
           "threads: the narrow phase's threads for the queries (0: all cores). solid: closed meshes as solids "
           "(an object wholly inside another touches it, at distance 0; open meshes are a ValueError), as "
           "trimesh does for convex meshes")
      .def("add_object", &PyScene::add_object, py::arg("name"), py::arg("mesh"), py::arg("transform") = py::none(),
           py::arg("group") = 1, py::arg("mask") = kAllGroups,
           "Adds (or, as trimesh, replaces) the object `name`: a Model, a Mesh or anything with .vertices and "
           ".faces, or a shape (tightbvh.shapes.Sphere, Box, Capsule, or a fitted tightbvh.Box, placed where it was "
           "fitted and moved by the transform), at `transform` (4x4, (R, t) or None), with collision filter bits `group` and `mask` (two "
           "objects are tested only when each one's group meets the other's mask). Returns the object's id.")
      .def("set_filter", &PyScene::set_filter, py::arg("name"), py::arg("group"), py::arg("mask"),
           "Sets the object's collision filter bits (ints in [0, 2**32)): a pair is tested only when "
           "(group_a & mask_b) and (group_b & mask_a); the query mesh of the _single calls ignores filters.")
      .def("filter", &PyScene::filter, py::arg("name"), "the object's filter bits: (group, mask)")
      .def("remove_object", &PyScene::remove_object, py::arg("name"))
      .def("set_transform", &PyScene::set_transform, py::arg("name"), py::arg("transform"))
      .def("set_transforms", &PyScene::set_transforms, py::arg("names"), py::arg("transforms"),
           "Moves many objects: names[i] to transforms[i] ((N, 4, 4) or (Rs, ts)); all checked before any moves.")
      .def(
          "allow", [](PyScene& s, py::handle a, py::handle b) { s.allow(a, b, true); }, py::arg("name_a"),
          py::arg("name_b"), "The pair may touch: never reported by in_collision_internal or min_distance_internal.")
      .def(
          "disallow", [](PyScene& s, py::handle a, py::handle b) { s.allow(a, b, false); }, py::arg("name_a"),
          py::arg("name_b"))
      .def("allowed", &PyScene::is_allowed, py::arg("name_a"), py::arg("name_b"))
      .def("in_collision_internal", &PyScene::in_collision_internal, py::arg("return_names") = false,
           py::arg("return_data") = false,
           "bool; with return_names a set of (name, name) tuples (each sorted); with return_data a list of "
           "ContactData (every touching triangle pair).")
      .def("in_collision_single", &PyScene::in_collision_single, py::arg("mesh"), py::arg("transform") = py::none(),
           py::arg("return_names") = false, py::arg("return_data") = false,
           "bool; with return_names the set of the names touching `mesh` (a mesh, a Model or a shape); with "
           "return_data a list of ContactData (the query object named '__external').")
      .def("in_collision_other", &PyScene::in_collision_other, py::arg("other_manager"),
           py::arg("return_names") = false, py::arg("return_data") = false,
           "bool; with return_names a set of (name in this scene, name in other) tuples; with return_data "
           "ContactData.")
      .def("min_distance_internal", &PyScene::min_distance_internal, py::arg("return_names") = false,
           py::arg("return_data") = false,
           "The least distance of two objects (0 when touching; inf with fewer than two objects); with "
           "return_names the (sorted) name pair, with return_data a DistanceData.")
      .def("min_distance_single", &PyScene::min_distance_single, py::arg("mesh"), py::arg("transform") = py::none(),
           py::arg("return_name") = false, py::arg("return_data") = false,
           "The least distance from `mesh` to an object; with return_name the closest object's name.")
      .def("min_distance_other", &PyScene::min_distance_other, py::arg("other_manager"),
           py::arg("return_names") = false, py::arg("return_data") = false,
           "The least distance between an object of this scene and one of `other_manager`; with return_names "
           "(name in this scene, name in other).")
      .def("distance_within_internal", &PyScene::distance_within_internal, py::arg("max_distance"),
           py::arg("return_data") = false,
           "Every tested object pair closer than max_distance (> 0; touching pairs at 0): a dict {(name, name) "
           "sorted: distance} in object order; with return_data also {(name, name): DistanceData}.")
      .def("distance_within_single", &PyScene::distance_within_single, py::arg("mesh"), py::arg("max_distance"),
           py::arg("transform") = py::none(), py::arg("return_data") = false,
           "Every object closer than max_distance to `mesh`: {name: distance}; with return_data also "
           "{name: DistanceData} (the query object named '__external').")
      .def("distance_within_other", &PyScene::distance_within_other, py::arg("other_manager"),
           py::arg("max_distance"), py::arg("return_data") = false,
           "Every object pair (one here, one in other_manager) closer than max_distance: {(name here, name "
           "there): distance}; with return_data also {(name here, name there): DistanceData}.")
      .def("in_collision_batch", &PyScene::in_collision_batch, py::arg("mesh"), py::arg("transforms"),
           "in_collision_single(mesh, T, return_names=True)[1] for every T in `transforms` ((N, 4, 4) or "
           "(Rs, ts)), on the scene's threads: a list of sets of names, in transform order.")
      .def_property_readonly("names", &PyScene::names, "the object names, in the order they were added")
      .def("transform", &PyScene::transform, py::arg("name"), "the object's 4x4 transform (a copy)")
      .def("model", &PyScene::model, py::arg("name"), "the object's Model")
      .def_property_readonly("model_count", &PyScene::model_count, "the number of distinct models")
      .def_property_readonly("model_bytes", &PyScene::model_bytes, "the heap bytes of the distinct models")
      .def_property_readonly("threads", &PyScene::threads)
      .def_property_readonly("solid", &PyScene::solid)
      .def("__reduce_ex__", &reduce_ex)
      .def(py::pickle([](const PyScene& s) { return s.state(); }, &PyScene::from_state))
      .def("__len__", &PyScene::size)
      .def("__contains__", &PyScene::contains)
      .def("__repr__", [](const PyScene& s) {
        return "<tightbvh.Scene: " + std::to_string(s.size()) + " objects, " + std::to_string(s.model_count()) +
               " models>";
      });
}

}  // namespace tightbvh::python
